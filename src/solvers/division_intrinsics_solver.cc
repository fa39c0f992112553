#include "src/solvers/division_intrinsics_solver.h"

#include <Eigen/Dense>
#include <cmath>

#include "src/solvers/radial_intrinsics.h"

namespace rig_calibrator {
namespace {

// Least squares A y = b with the columns of A scaled to unit norm, which makes
// the rank test and the solve independent of the units of the unknowns.
bool SolveEquilibratedLeastSquares(const Eigen::MatrixXd& A,
                                   const Eigen::VectorXd& b,
                                   Eigen::VectorXd* y) {
  const Eigen::VectorXd column_norms = A.colwise().norm();
  if (!column_norms.allFinite() || !b.allFinite() ||
      (column_norms.array() <= 0).any()) {
    return false;
  }
  const Eigen::VectorXd column_scales = column_norms.cwiseInverse();
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(
      A * column_scales.asDiagonal());
  if (qr.rank() < A.cols()) {
    return false;
  }
  *y = column_scales.asDiagonal() * qr.solve(b);
  return y->allFinite();
}

}  // namespace

bool SolveDivisionIntrinsics(const std::vector<Eigen::Vector2d>& x,
                             const std::vector<Eigen::Vector3d>& points_cam,
                             const int num_kappa, DivisionIntrinsics* model) {
  const int num_points = static_cast<int>(x.size());
  const int num_unknowns = num_kappa + 2;
  if (num_kappa < 0 || num_kappa > 2 || points_cam.size() != x.size() ||
      num_points < num_unknowns) {
    return false;
  }
  double sum_squared_rho = 0;
  for (const Eigen::Vector2d& point : x) {
    sum_squared_rho += point.squaredNorm();
  }
  // With rho = sigma rho~, the model keeps its form with f~ = f / sigma and
  // kappa~_j = kappa_j sigma^(2j), which keeps rho~^4 near 1.
  const double sigma = std::sqrt(sum_squared_rho / num_points);
  if (!(sigma > 0)) {
    return false;
  }
  Eigen::MatrixXd A(num_points, num_unknowns);
  Eigen::VectorXd b(num_points);
  for (int i = 0; i < num_points; ++i) {
    const double rho = x[i].norm() / sigma;
    const double s = SignedRadialCoordinate(x[i], points_cam[i]);
    double rho_power = 1;
    for (int j = 0; j <= num_kappa; ++j) {
      A(i, j) = s * rho_power;
      rho_power *= rho * rho;
    }
    A(i, num_unknowns - 1) = -rho;
    b(i) = rho * points_cam[i].z();
  }
  Eigen::VectorXd y;
  if (!SolveEquilibratedLeastSquares(A, b, &y) || !(y(0) > 0)) {
    return false;
  }
  model->num_kappa = num_kappa;
  model->focal = y(0) * sigma;
  model->tz = y(num_unknowns - 1);
  model->kappa[0] = model->kappa[1] = 0;
  double sigma_power = sigma * sigma;
  for (int j = 1; j <= num_kappa; ++j) {
    model->kappa[j - 1] = y(j) / y(0) / sigma_power;
    sigma_power *= sigma * sigma;
  }
  return true;
}

}  // namespace rig_calibrator
