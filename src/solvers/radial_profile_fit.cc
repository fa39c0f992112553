#include "src/solvers/radial_profile_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

namespace rig_calibrator {
namespace {

// Smallest Cholesky pivot (a square root, so ~1e-14 in the eigenvalues) of
// the equilibrated normal equations.
constexpr double kMinCholeskyPivot = 1e-7;

// FitRadialProfile with a fixed number of linear unknowns: y = [f, f k1, ..]
// (kNumUnknowns = num_radial_terms + 1), or [f k1, ..] for a known f
// (kNumUnknowns = num_radial_terms, the basis starting at phi^3 and f phi
// moved to the target). The least-squares upgrade calls it hundreds of times
// per estimate: normal equations in fixed-size matrices, then the residuals
// in a second pass (no cancellation in the error).
template <int kNumUnknowns>
bool FitRadialProfileWithUnknowns(
    const std::vector<Eigen::Vector2d>& x,
    const std::vector<Eigen::Vector3d>& points_cam,
    const std::optional<double>& known_focal, RadialIntrinsics* model,
    double* squared_error) {
  typedef Eigen::Matrix<double, kNumUnknowns, 1> Vector;
  typedef Eigen::Matrix<double, kNumUnknowns, kNumUnknowns> Matrix;
  const int num_points = static_cast<int>(x.size());
  if (num_points < std::max(kNumUnknowns, 1)) {
    return false;
  }
  const double focal_term = known_focal ? *known_focal : 0;
  // The basis [phi, phi^3, ..] (or [phi^3, phi^5, ..] for a known f) of
  // point i and its target rho_i - focal_term phi_i.
  const auto basis = [&](const int i, double* target) {
    const double phi = ProfileAngle(model->profile,
                                    SignedRadialCoordinate(x[i], points_cam[i]),
                                    points_cam[i].z() + model->tz);
    *target = x[i].norm() - focal_term * phi;
    Vector row;
    double phi_power = known_focal ? phi * phi * phi : phi;
    for (int j = 0; j < kNumUnknowns; ++j) {
      row(j) = phi_power;
      phi_power *= phi * phi;
    }
    return row;
  };
  Vector beta;
  if constexpr (kNumUnknowns > 0) {
    Matrix AtA = Matrix::Zero();
    Vector Atb = Vector::Zero();
    for (int i = 0; i < num_points; ++i) {
      if (!(points_cam[i].z() + model->tz > 0)) {
        return false;
      }
      double target = 0;
      const Vector row = basis(i, &target);
      AtA.noalias() += row * row.transpose();
      Atb.noalias() += target * row;
    }
    const Vector diagonal = AtA.diagonal();
    if (!AtA.allFinite() || !Atb.allFinite() || (diagonal.array() <= 0).any()) {
      return false;
    }
    // Equilibrated to a unit diagonal, so that a small Cholesky pivot means a
    // nearly dependent basis whatever the magnitudes of phi, phi^3, phi^5.
    const Vector scales = diagonal.cwiseSqrt().cwiseInverse();
    const Eigen::LLT<Matrix> llt(scales.asDiagonal() * AtA *
                                 scales.asDiagonal());
    if (llt.info() != Eigen::Success ||
        !(llt.matrixLLT().diagonal().minCoeff() > kMinCholeskyPivot)) {
      return false;
    }
    beta = scales.asDiagonal() * llt.solve(scales.asDiagonal() * Atb);
    if (!beta.allFinite() || (!known_focal && !(beta(0) > 0))) {
      return false;
    }
  }
  *squared_error = 0;
  for (int i = 0; i < num_points; ++i) {
    if (!(points_cam[i].z() + model->tz > 0)) {
      return false;
    }
    double target = 0;
    const Vector row = basis(i, &target);
    double residual = target;
    if constexpr (kNumUnknowns > 0) residual -= row.dot(beta);
    *squared_error += residual * residual;
  }
  // y = [f, f k1, f k2] or, for a known f, [f k1, f k2].
  model->k[0] = model->k[1] = 0;
  if constexpr (kNumUnknowns > 0) {
    const int num_focal_unknowns = known_focal ? 0 : 1;
    model->focal = known_focal ? *known_focal : beta(0);
    for (int j = num_focal_unknowns; j < kNumUnknowns; ++j) {
      model->k[j - num_focal_unknowns] = beta(j) / model->focal;
    }
  } else {
    model->focal = *known_focal;
  }
  return std::isfinite(*squared_error);
}

// One Gauss-Newton step of RefineRadialProfileAndTz from `model`: the new tz
// and y = [f, f k1, f k2] in `next`, with f held if `hold_focal`. False for a
// rank-deficient Jacobian.
bool GaussNewtonStep(const std::vector<Eigen::Vector2d>& x,
                     const std::vector<Eigen::Vector3d>& points_cam,
                     const bool hold_focal, const RadialIntrinsics& model,
                     RadialIntrinsics* next) {
  const int num_points = static_cast<int>(x.size());
  const int num_terms = model.num_radial_terms + 1;  // in y
  Eigen::VectorXd y(num_terms);
  y(0) = model.focal;
  for (int j = 1; j < num_terms; ++j) y(j) = model.focal * model.k[j - 1];
  // Columns: tz, then y (J(i, 1 + j) = phi^(2j+1)); a held f drops column 1.
  Eigen::MatrixXd J(num_points, 1 + num_terms);
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
    for (int j = 0; j < num_terms; ++j) {
      J(i, 1 + j) = phi_even_power * phi;
      radius += y(j) * phi_even_power * phi;
      dradius_dphi += (2 * j + 1) * y(j) * phi_even_power;
      phi_even_power *= phi * phi;
    }
    J(i, 0) = dradius_dphi * dphi_dtz;
    residuals(i) = radius - x[i].norm();
  }
  if (hold_focal) {
    J.block(0, 1, num_points, num_terms - 1) =
        J.rightCols(num_terms - 1).eval();
    J.conservativeResize(Eigen::NoChange, num_terms);
  }
  const Eigen::VectorXd column_norms = J.colwise().norm();
  if (!J.allFinite() || (column_norms.array() <= 0).any()) {
    return false;
  }
  const Eigen::VectorXd scales = column_norms.cwiseInverse();
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(J * scales.asDiagonal());
  if (qr.rank() < J.cols()) {
    return false;
  }
  Eigen::VectorXd step = scales.asDiagonal() * qr.solve(-residuals);
  if (hold_focal) {  // back to the columns tz, y with a zero step in f
    step.conservativeResize(2 + num_terms - 1);
    step.tail(num_terms - 1) = step.segment(1, num_terms - 1).eval();
    step(1) = 0;
  }
  *next = model;
  next->tz = model.tz + step(0);
  const double focal = y(0) + step(1);
  next->focal = focal;
  for (int j = 1; j < num_terms; ++j) {
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
                      const std::optional<double>& known_focal,
                      RadialIntrinsics* model, double* squared_error) {
  if (points_cam.size() != x.size() || model->num_radial_terms < 0 ||
      model->num_radial_terms > 2 ||
      (known_focal && !(std::isfinite(*known_focal) && *known_focal > 0))) {
    return false;
  }
  switch (model->num_radial_terms + (known_focal ? 0 : 1)) {
    case 0:
      return FitRadialProfileWithUnknowns<0>(x, points_cam, known_focal, model,
                                             squared_error);
    case 1:
      return FitRadialProfileWithUnknowns<1>(x, points_cam, known_focal, model,
                                             squared_error);
    case 2:
      return FitRadialProfileWithUnknowns<2>(x, points_cam, known_focal, model,
                                             squared_error);
    default:
      return FitRadialProfileWithUnknowns<3>(x, points_cam, known_focal, model,
                                             squared_error);
  }
}

bool RefineRadialProfileAndTz(const std::vector<Eigen::Vector2d>& x,
                              const std::vector<Eigen::Vector3d>& points_cam,
                              const std::optional<double>& known_focal,
                              const int max_num_iterations,
                              RadialIntrinsics* model, double* squared_error) {
  RadialIntrinsics best = *model;
  double best_error = 0;
  if (!FitRadialProfile(x, points_cam, known_focal, &best, &best_error)) {
    return false;
  }
  for (int iteration = 0; iteration < max_num_iterations; ++iteration) {
    RadialIntrinsics next;
    if (!GaussNewtonStep(x, points_cam, known_focal.has_value(), best, &next)) {
      break;
    }
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
