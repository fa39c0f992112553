#include "src/solvers/radial_profile_fit.h"

#include <Eigen/Dense>
#include <cmath>
#include <limits>

namespace rig_calibrator {
namespace {

// Smallest Cholesky pivot (a square root, so ~1e-14 in the eigenvalues) of
// the equilibrated normal equations.
constexpr double kMinCholeskyPivot = 1e-7;

// FitRadialProfile with a fixed number of radial terms. The least-squares
// upgrade calls it hundreds of times per estimate: normal equations in
// fixed-size matrices, then the residuals in a second pass (no cancellation
// in the error).
template <int kNumRadialTerms>
bool FitRadialProfileWithTerms(const std::vector<Eigen::Vector2d>& x,
                               const std::vector<Eigen::Vector3d>& points_cam,
                               RadialIntrinsics* model, double* squared_error) {
  constexpr int kNumUnknowns = kNumRadialTerms + 1;
  typedef Eigen::Matrix<double, kNumUnknowns, 1> Vector;
  typedef Eigen::Matrix<double, kNumUnknowns, kNumUnknowns> Matrix;
  const int num_points = static_cast<int>(x.size());
  if (num_points < kNumUnknowns) {
    return false;
  }
  // [phi, phi^3, phi^5] of point i.
  const auto basis = [&](const int i) {
    const double phi = ProfileAngle(model->profile,
                                    SignedRadialCoordinate(x[i], points_cam[i]),
                                    points_cam[i].z() + model->tz);
    Vector row;
    double phi_power = phi;
    for (int j = 0; j < kNumUnknowns; ++j) {
      row(j) = phi_power;
      phi_power *= phi * phi;
    }
    return row;
  };
  Matrix AtA = Matrix::Zero();
  Vector Atb = Vector::Zero();
  for (int i = 0; i < num_points; ++i) {
    if (!(points_cam[i].z() + model->tz > 0)) {
      return false;
    }
    const Vector row = basis(i);
    AtA.noalias() += row * row.transpose();
    Atb.noalias() += x[i].norm() * row;
  }
  const Vector diagonal = AtA.diagonal();
  if (!AtA.allFinite() || !Atb.allFinite() || (diagonal.array() <= 0).any()) {
    return false;
  }
  // Equilibrated to a unit diagonal, so that a small Cholesky pivot means a
  // nearly dependent basis whatever the magnitudes of phi, phi^3, phi^5.
  const Vector scales = diagonal.cwiseSqrt().cwiseInverse();
  const Eigen::LLT<Matrix> llt(scales.asDiagonal() * AtA * scales.asDiagonal());
  if (llt.info() != Eigen::Success ||
      !(llt.matrixLLT().diagonal().minCoeff() > kMinCholeskyPivot)) {
    return false;
  }
  const Vector beta =
      scales.asDiagonal() * llt.solve(scales.asDiagonal() * Atb);
  if (!beta.allFinite() || !(beta(0) > 0)) {
    return false;
  }
  *squared_error = 0;
  for (int i = 0; i < num_points; ++i) {
    const double residual = x[i].norm() - basis(i).dot(beta);
    *squared_error += residual * residual;
  }
  model->focal = beta(0);
  model->k[0] = model->k[1] = 0;
  for (int j = 1; j < kNumUnknowns; ++j) {
    model->k[j - 1] = beta(j) / beta(0);
  }
  return std::isfinite(*squared_error);
}

// One Gauss-Newton step of RefineRadialProfileAndTz from `model`: the new tz
// and y = [f, f k1, f k2] in `next`. False for a rank-deficient Jacobian.
bool GaussNewtonStep(const std::vector<Eigen::Vector2d>& x,
                     const std::vector<Eigen::Vector3d>& points_cam,
                     const RadialIntrinsics& model, RadialIntrinsics* next) {
  const int num_points = static_cast<int>(x.size());
  const int num_unknowns = model.num_radial_terms + 2;  // tz, y
  Eigen::VectorXd y(num_unknowns - 1);
  y(0) = model.focal;
  for (int j = 1; j < num_unknowns - 1; ++j)
    y(j) = model.focal * model.k[j - 1];
  Eigen::MatrixXd J(num_points, num_unknowns);
  Eigen::VectorXd residuals(num_points);
  for (int i = 0; i < num_points; ++i) {
    const double s = SignedRadialCoordinate(x[i], points_cam[i]);
    const double depth = points_cam[i].z() + model.tz;
    const double phi = ProfileAngle(model.profile, s, depth);
    const double dphi_dtz = model.profile == RadialProfile::kPolynomial
                                ? -s / (depth * depth)
                                : -s / (s * s + depth * depth);
    // r_d = sum_j y_j phi^(2j+1), d r_d / d phi = sum_j (2j+1) y_j phi^(2j).
    double radius = 0, dradius_dphi = 0, phi_even_power = 1;
    for (int j = 0; j < num_unknowns - 1; ++j) {
      J(i, 1 + j) = phi_even_power * phi;
      radius += y(j) * phi_even_power * phi;
      dradius_dphi += (2 * j + 1) * y(j) * phi_even_power;
      phi_even_power *= phi * phi;
    }
    J(i, 0) = dradius_dphi * dphi_dtz;
    residuals(i) = radius - x[i].norm();
  }
  const Eigen::VectorXd column_norms = J.colwise().norm();
  if (!J.allFinite() || (column_norms.array() <= 0).any()) {
    return false;
  }
  const Eigen::VectorXd scales = column_norms.cwiseInverse();
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(J * scales.asDiagonal());
  if (qr.rank() < num_unknowns) {
    return false;
  }
  const Eigen::VectorXd step = scales.asDiagonal() * qr.solve(-residuals);
  *next = model;
  next->tz = model.tz + step(0);
  const double focal = y(0) + step(1);
  next->focal = focal;
  for (int j = 1; j < num_unknowns - 1; ++j) {
    next->k[j - 1] = (y(j) + step(1 + j)) / focal;
  }
  return step.allFinite();
}

// Sum of squared radial residuals of `model`; infinite if a point has
// c + tz <= 0.
double RadialSquaredError(const std::vector<Eigen::Vector2d>& x,
                          const std::vector<Eigen::Vector3d>& points_cam,
                          const RadialIntrinsics& model) {
  double squared_error = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    const double depth = points_cam[i].z() + model.tz;
    if (!(depth > 0)) {
      return std::numeric_limits<double>::infinity();
    }
    const double phi = ProfileAngle(
        model.profile, SignedRadialCoordinate(x[i], points_cam[i]), depth);
    const double phi2 = phi * phi;
    const double residual =
        model.focal * phi * (1 + model.k[0] * phi2 + model.k[1] * phi2 * phi2) -
        x[i].norm();
    squared_error += residual * residual;
  }
  return squared_error;
}

}  // namespace

bool FitRadialProfile(const std::vector<Eigen::Vector2d>& x,
                      const std::vector<Eigen::Vector3d>& points_cam,
                      RadialIntrinsics* model, double* squared_error) {
  if (points_cam.size() != x.size()) {
    return false;
  }
  switch (model->num_radial_terms) {
    case 0:
      return FitRadialProfileWithTerms<0>(x, points_cam, model, squared_error);
    case 1:
      return FitRadialProfileWithTerms<1>(x, points_cam, model, squared_error);
    case 2:
      return FitRadialProfileWithTerms<2>(x, points_cam, model, squared_error);
    default:
      return false;
  }
}

bool RefineRadialProfileAndTz(const std::vector<Eigen::Vector2d>& x,
                              const std::vector<Eigen::Vector3d>& points_cam,
                              const int max_num_iterations,
                              RadialIntrinsics* model, double* squared_error) {
  RadialIntrinsics best = *model;
  double best_error = 0;
  if (!FitRadialProfile(x, points_cam, &best, &best_error)) {
    return false;
  }
  for (int iteration = 0; iteration < max_num_iterations; ++iteration) {
    RadialIntrinsics next;
    if (!GaussNewtonStep(x, points_cam, best, &next)) break;
    const double next_error = RadialSquaredError(x, points_cam, next);
    if (!(next_error < best_error)) break;
    const bool converged = next.tz == best.tz;
    best = next;
    best_error = next_error;
    if (converged) break;
  }
  *model = best;
  *squared_error = best_error;
  return true;
}

}  // namespace rig_calibrator
