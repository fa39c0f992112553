#include "src/solvers/radial_pose_solver.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>

#include "src/geometry/point_normalization.h"

namespace rig_calibrator {
namespace {

using Vector8d = Eigen::Matrix<double, 8, 1>;

// Two Newton steps on c[0] + c[1] x + ... + c[degree] x^degree: the closed
// forms below lose a few digits near clustered roots; this restores them.
double PolishRoot(const double* c, int degree, double x) {
  for (int iter = 0; iter < 2; ++iter) {
    double value = c[degree];
    double derivative = 0;
    for (int k = degree - 1; k >= 0; --k) {
      derivative = derivative * x + value;
      value = value * x + c[k];
    }
    if (derivative == 0 || !std::isfinite(derivative)) break;
    const double step = value / derivative;
    if (!std::isfinite(step)) break;
    x -= step;
  }
  return x;
}

// Real roots of c2 x^2 + c1 x + c0, degrading to the linear case when c2
// vanishes. A discriminant that is negative only at rounding level is a
// double root and is clamped to 0. The product form avoids cancellation in
// the smaller root.
int SolveQuadraticReal(double c2, double c1, double c0, double roots[2]) {
  if (c2 == 0) {
    if (c1 == 0) return 0;
    roots[0] = -c0 / c1;
    return 1;
  }
  double discriminant = c1 * c1 - 4 * c2 * c0;
  if (discriminant < 0) {
    if (discriminant < -1e-12 * (c1 * c1 + std::abs(4 * c2 * c0))) return 0;
    discriminant = 0;
  }
  const double q = -0.5 * (c1 + std::copysign(std::sqrt(discriminant), c1));
  if (q == 0) {
    roots[0] = 0;
    return 1;
  }
  roots[0] = q / c2;
  roots[1] = c0 / q;
  return 2;
}

// Real roots of x^3 + a2 x^2 + a1 x + a0 (trigonometric form for three real
// roots, Cardano otherwise).
int SolveMonicCubicReal(double a2, double a1, double a0, double roots[3]) {
  const double q = (a2 * a2 - 3 * a1) / 9;
  const double r = (2 * a2 * a2 * a2 - 9 * a2 * a1 + 27 * a0) / 54;
  const double shift = a2 / 3;
  int num_roots;
  if (r * r < q * q * q) {
    const double theta =
        std::acos(std::clamp(r / std::sqrt(q * q * q), -1.0, 1.0));
    const double scale = -2 * std::sqrt(q);
    roots[0] = scale * std::cos(theta / 3) - shift;
    roots[1] = scale * std::cos((theta + 2 * M_PI) / 3) - shift;
    roots[2] = scale * std::cos((theta - 2 * M_PI) / 3) - shift;
    num_roots = 3;
  } else {
    const double a = -std::copysign(
        std::cbrt(std::abs(r) + std::sqrt(r * r - q * q * q)), r);
    const double b = a == 0 ? 0 : q / a;
    roots[0] = a + b - shift;
    num_roots = 1;
  }
  const double coeffs[4] = {a0, a1, a2, 1};
  for (int i = 0; i < num_roots; ++i) {
    roots[i] = PolishRoot(coeffs, 3, roots[i]);
  }
  return num_roots;
}

// Real roots of c[0] + c[1] x + c[2] x^2 + c[3] x^3 + c[4] x^4 by Ferrari's
// method: depress to y^4 + p y^2 + q y + r (x = y - b/4), take the largest
// root m of the resolvent cubic m^3 + p m^2 + (p^2/4 - r) m - q^2/8 = 0, and
// split into the two quadratics
//   y^2 -+ sqrt(2m) y + (p/2 + m +- q / (2 sqrt(2m))) = 0.
// Leading coefficients that are negligible relative to the others lower the
// degree (the lost roots are at infinity).
int SolveQuarticReal(const double c_in[5], double roots[4]) {
  double max_abs = 0;
  for (int k = 0; k < 5; ++k) max_abs = std::max(max_abs, std::abs(c_in[k]));
  if (!(max_abs > 0) || !std::isfinite(max_abs)) return 0;
  double c[5];
  for (int k = 0; k < 5; ++k) c[k] = c_in[k] / max_abs;
  constexpr double kNegligible = 1e-13;
  if (std::abs(c[4]) < kNegligible) {
    if (std::abs(c[3]) < kNegligible) {
      return SolveQuadraticReal(c[2], c[1], c[0], roots);
    }
    return SolveMonicCubicReal(c[2] / c[3], c[1] / c[3], c[0] / c[3], roots);
  }
  const double b = c[3] / c[4];
  const double cc = c[2] / c[4];
  const double d = c[1] / c[4];
  const double e = c[0] / c[4];
  const double b2 = b * b;
  const double p = cc - 3 * b2 / 8;
  const double q = d - b * cc / 2 + b2 * b / 8;
  const double r = e - b * d / 4 + b2 * cc / 16 - 3 * b2 * b2 / 256;

  double resolvent_roots[3];
  const int num_resolvent =
      SolveMonicCubicReal(p, p * p / 4 - r, -q * q / 8, resolvent_roots);
  const double m =
      *std::max_element(resolvent_roots, resolvent_roots + num_resolvent);

  int num_roots = 0;
  double y[4];
  if (m > 1e-14 * (1 + std::abs(p) + std::sqrt(std::abs(r)))) {
    const double s = std::sqrt(2 * m);
    const double offset = q / (2 * s);
    num_roots += SolveQuadraticReal(1, -s, p / 2 + m + offset, y + num_roots);
    num_roots += SolveQuadraticReal(1, s, p / 2 + m - offset, y + num_roots);
  } else {
    // q ~ 0: biquadratic y^4 + p y^2 + r = 0.
    double y_sq[2];
    const int num_y_sq = SolveQuadraticReal(1, p, r, y_sq);
    for (int i = 0; i < num_y_sq; ++i) {
      if (y_sq[i] < 0) continue;
      y[num_roots++] = std::sqrt(y_sq[i]);
      y[num_roots++] = -std::sqrt(y_sq[i]);
    }
  }
  const double monic[5] = {e, d, cc, b, 1};
  for (int i = 0; i < num_roots; ++i) {
    roots[i] = PolishRoot(monic, 4, y[i] - b / 4);
  }
  return num_roots;
}

// Polynomials in a, as coefficient arrays in increasing degree.
template <int N, int M>
Eigen::Matrix<double, N + M - 1, 1> PolyMul(
    const Eigen::Matrix<double, N, 1>& f,
    const Eigen::Matrix<double, M, 1>& g) {
  Eigen::Matrix<double, N + M - 1, 1> h =
      Eigen::Matrix<double, N + M - 1, 1>::Zero();
  for (int i = 0; i < N; ++i) {
    for (int j = 0; j < M; ++j) h(i + j) += f(i) * g(j);
  }
  return h;
}

}  // namespace

bool NormalizeRadialRows(Vector8d* p) {
  Eigen::Matrix<double, 2, 3> rows;
  rows.row(0) = p->segment<3>(0).transpose();
  rows.row(1) = p->segment<3>(4).transpose();
  // Polar decomposition through the 2x2 Gram matrix G = M M^T = U S^2 U^T:
  // U V^T = G^(-1/2) M.
  const Eigen::Matrix2d gram = rows * rows.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen;
  eigen.computeDirect(gram);
  const Eigen::Vector2d singular_sq = eigen.eigenvalues();
  if (!(singular_sq(0) > 1e-20 * singular_sq(1)) ||
      !std::isfinite(singular_sq(1))) {
    return false;
  }
  const Eigen::Vector2d singular = singular_sq.cwiseSqrt();
  const Eigen::Matrix2d inv_sqrt_gram = eigen.eigenvectors() *
                                        singular.cwiseInverse().asDiagonal() *
                                        eigen.eigenvectors().transpose();
  const Eigen::Matrix<double, 2, 3> orthonormal = inv_sqrt_gram * rows;
  const double scale = 0.5 * (singular(0) + singular(1));
  p->segment<3>(0) = orthonormal.row(0).transpose();
  p->segment<3>(4) = orthonormal.row(1).transpose();
  (*p)(3) /= scale;
  (*p)(7) /= scale;
  return p->allFinite();
}

int RadialPosesInSubspace(const Eigen::Matrix<double, 8, 3>& basis,
                          Vector8d solutions[4]) {
  // The constraints as symmetric bilinear forms on the basis coefficients:
  //   g1(p) = r1.r2,  g2(p) = |r1|^2 - |r2|^2,
  // C1(j,k) = g1-form(n_j, n_k), C2(j,k) = g2-form(n_j, n_k).
  Eigen::Matrix3d c1, c2;
  for (int j = 0; j < 3; ++j) {
    for (int k = j; k < 3; ++k) {
      const auto r1j = basis.col(j).segment<3>(0);
      const auto r2j = basis.col(j).segment<3>(4);
      const auto r1k = basis.col(k).segment<3>(0);
      const auto r2k = basis.col(k).segment<3>(4);
      c1(j, k) = c1(k, j) = 0.5 * (r1j.dot(r2k) + r1k.dot(r2j));
      c2(j, k) = c2(k, j) = r1j.dot(r1k) - r2j.dot(r2k);
    }
  }
  // With p = a n0 + b n1 + n2 each constraint is g = G2 b^2 + G1(a) b + G0(a):
  //   G2 = C11, G1 = 2 C12 + 2 C01 a, G0 = C22 + 2 C02 a + C00 a^2.
  const double a2 = c1(1, 1);
  const double b2 = c2(1, 1);
  const Eigen::Vector2d a1(2 * c1(1, 2), 2 * c1(0, 1));
  const Eigen::Vector2d b1(2 * c2(1, 2), 2 * c2(0, 1));
  const Eigen::Vector3d a0(c1(2, 2), 2 * c1(0, 2), c1(0, 0));
  const Eigen::Vector3d b0(c2(2, 2), 2 * c2(0, 2), c2(0, 0));
  // Sylvester resultant of the two quadratics in b:
  //   Res(a) = (A2 B0 - A0 B2)^2 - (A2 B1 - A1 B2)(A1 B0 - A0 B1),
  // a quartic in a whose real roots are the candidate a.
  const Eigen::Vector3d d0 = a2 * b0 - b2 * a0;
  const Eigen::Vector2d d1 = a2 * b1 - b2 * a1;
  const Eigen::Vector4d e = PolyMul<2, 3>(a1, b0) - PolyMul<3, 2>(a0, b1);
  const Eigen::Matrix<double, 5, 1> resultant =
      PolyMul<3, 3>(d0, d0) - PolyMul<2, 4>(d1, e);

  double a_roots[4];
  const int num_a = SolveQuarticReal(resultant.data(), a_roots);
  int num_solutions = 0;
  for (int i = 0; i < num_a; ++i) {
    const double a = a_roots[i];
    const double g1_1 = a1(0) + a1(1) * a;
    const double g1_0 = a0(0) + (a0(1) + a0(2) * a) * a;
    const double g2_1 = b1(0) + b1(1) * a;
    const double g2_0 = b0(0) + (b0(1) + b0(2) * a) * a;
    // b is the root shared by g1 and g2: take g1's roots and keep the one
    // that satisfies g2 best.
    double b_roots[2];
    const int num_b = SolveQuadraticReal(a2, g1_1, g1_0, b_roots);
    if (num_b == 0) continue;
    double best_b = b_roots[0];
    double best_g2 = std::numeric_limits<double>::infinity();
    for (int k = 0; k < num_b; ++k) {
      const double b = b_roots[k];
      const double g2 = std::abs((b2 * b + g2_1) * b + g2_0);
      if (g2 < best_g2) {
        best_g2 = g2;
        best_b = b;
      }
    }
    Vector8d p = a * basis.col(0) + best_b * basis.col(1) + basis.col(2);
    if (NormalizeRadialRows(&p)) solutions[num_solutions++] = p;
  }
  return num_solutions;
}

void SolveRadialPose5(const std::vector<Eigen::Vector2d>& points2D,
                      const std::vector<Eigen::Vector3d>& points3D,
                      std::vector<Rigid3d>* cam_from_world) {
  constexpr int kNumPoints = 5;
  if (points2D.size() != kNumPoints || points3D.size() != kNumPoints) return;

  std::vector<Eigen::Vector3d> points3D_normalized;
  Eigen::Vector3d centroid;
  double scale;
  if (!CenterAndScalePoints(points3D, &points3D_normalized, &centroid,
                            &scale)) {
    return;
  }

  Eigen::Matrix<double, 3, kNumPoints> X_normalized;
  Eigen::Matrix<double, 2, kNumPoints> x_normalized;
  // Transposed 5x8 system: column i is (-v X, -v, u X, u) of point i.
  Eigen::Matrix<double, 8, kNumPoints> system_t;
  for (int i = 0; i < kNumPoints; ++i) {
    const double norm = points2D[i].norm();
    if (!(norm > 0) || !std::isfinite(norm)) return;
    x_normalized.col(i) = points2D[i] / norm;
    X_normalized.col(i) = points3D_normalized[i];
    const double u = x_normalized(0, i);
    const double v = x_normalized(1, i);
    system_t.col(i) << -v * X_normalized.col(i), -v, u * X_normalized.col(i), u;
  }
  // A^T = Q R: the last 3 columns of Q span the null space of A.
  const Eigen::HouseholderQR<Eigen::Matrix<double, 8, kNumPoints>> qr(system_t);
  const Eigen::Matrix<double, 8, 8> q = qr.householderQ();
  const Eigen::Matrix<double, 8, 3> null_space = q.rightCols<3>();

  Vector8d solutions[4];
  const int num_solutions = RadialPosesInSubspace(null_space, solutions);
  for (int s = 0; s < num_solutions; ++s) {
    Vector8d& p = solutions[s];
    // p and -p fit the same lines; keep the sign that puts every sample on
    // its half-line, (r1.X + t1, r2.X + t2) . x > 0, and drop solutions that
    // split the sample.
    int num_positive = 0;
    for (int i = 0; i < kNumPoints; ++i) {
      const double a = p.segment<3>(0).dot(X_normalized.col(i)) + p(3);
      const double b = p.segment<3>(4).dot(X_normalized.col(i)) + p(7);
      if (a * x_normalized(0, i) + b * x_normalized(1, i) > 0) ++num_positive;
    }
    if (num_positive == 0) {
      p = -p;
    } else if (num_positive != kNumPoints) {
      continue;
    }
    Eigen::Matrix3d rotation;
    rotation.row(0) = p.segment<3>(0).transpose();
    rotation.row(1) = p.segment<3>(4).transpose();
    rotation.row(2) = rotation.row(0).cross(rotation.row(1));
    // Undo X_normalized = (X - c) / s: R X + t = s (R X_normalized + t_n)
    // with t = s t_n - R c; the positive factor s keeps the half-lines.
    const Eigen::Vector3d rotated_centroid = rotation * centroid;
    const Eigen::Vector3d translation(scale * p(3) - rotated_centroid(0),
                                      scale * p(7) - rotated_centroid(1), 0);
    if (!rotation.allFinite() || !translation.allFinite()) continue;
    cam_from_world->emplace_back(rotation, translation);
  }
}

}  // namespace rig_calibrator
