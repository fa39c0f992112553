#include "src/intrinsics_solvers.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace rig_calibrator {
namespace {

// Residual of a point the model cannot project. COLMAP's support measurers
// compare residuals against the squared threshold and MSAC truncates them,
// so the largest finite double marks an outlier without producing inf/NaN.
constexpr double kInvalidResidual = std::numeric_limits<double>::max();

// Log-spaced grid over the depth of the nearest point for the variable
// projection: kNumGridPoints from 1/kGridRange to kGridRange times the
// division model's value (a factor 1.15 between neighbours).
constexpr int kNumGridPoints = 49;
constexpr double kGridRange = 30;
// Local minima of the grid refined, and solutions returned.
constexpr size_t kMaxNumRefinedMinima = 5;
constexpr size_t kMaxNumCandidates = 3;
// Golden-section search stops when the bracket has shrunk by this factor.
constexpr double kRelativeTzTolerance = 1e-10;

// s = x.(a, b) / |x|, the signed radial coordinate of the 3D point along the
// image point's direction; 0 for a point on the principal point, which
// carries no radial information.
double SignedRadialCoordinate(const Eigen::Vector2d& x,
                              const Eigen::Vector3d& point_cam) {
  const double rho = x.norm();
  return rho > 0 ? x.dot(point_cam.head<2>()) / rho : 0.0;
}

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

double Median(std::vector<double> values) {
  const size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + middle, values.end());
  return values[middle];
}

// E(tz) of the variable projection; infinite where FitRadialProfile fails.
double ProfileError(const std::vector<Eigen::Vector2d>& x,
                    const std::vector<Eigen::Vector3d>& points_cam,
                    RadialIntrinsics model, double tz) {
  model.tz = tz;
  double squared_error = 0;
  if (!FitRadialProfile(x, points_cam, &model, &squared_error)) {
    return std::numeric_limits<double>::infinity();
  }
  return squared_error;
}

// Golden-section search for the minimum of E over [lo, hi].
double MinimizeProfileError(const std::vector<Eigen::Vector2d>& x,
                            const std::vector<Eigen::Vector3d>& points_cam,
                            const RadialIntrinsics& model, double lo, double hi,
                            double tolerance) {
  const double ratio = (std::sqrt(5.0) - 1) / 2;
  double x1 = hi - ratio * (hi - lo);
  double x2 = lo + ratio * (hi - lo);
  double e1 = ProfileError(x, points_cam, model, x1);
  double e2 = ProfileError(x, points_cam, model, x2);
  while (hi - lo > tolerance) {
    if (e1 < e2) {
      hi = x2;
      x2 = x1;
      e2 = e1;
      x1 = hi - ratio * (hi - lo);
      e1 = ProfileError(x, points_cam, model, x1);
    } else {
      lo = x1;
      x1 = x2;
      e1 = e2;
      x2 = lo + ratio * (hi - lo);
      e2 = ProfileError(x, points_cam, model, x2);
    }
  }
  return e1 < e2 ? x1 : x2;
}

}  // namespace

double RadialIntrinsics::DistortedRadius(const double q) const {
  const double phi = profile == RadialProfile::kPolynomial ? q : std::atan(q);
  const double phi2 = phi * phi;
  return focal * phi * (1 + k[0] * phi2 + k[1] * phi2 * phi2);
}

bool RadialIntrinsics::Project(const Eigen::Vector3d& point_cam,
                               Eigen::Vector2d* x) const {
  const double depth = point_cam.z() + tz;
  if (!(depth > 0)) {
    return false;
  }
  // x = r_d(q) (a, b) / |(a, b)| with q = |(a, b)| / depth, written as
  // (r_d(q) / q) (a, b) / depth so that it stays finite on the optical axis,
  // where r_d(q) / q -> f.
  const double q = point_cam.head<2>().norm() / depth;
  const double radius_over_q = q > std::numeric_limits<double>::epsilon()
                                   ? DistortedRadius(q) / q
                                   : focal;
  *x = radius_over_q / depth * point_cam.head<2>();
  return true;
}

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

bool FitRadialProfile(const std::vector<Eigen::Vector2d>& x,
                      const std::vector<Eigen::Vector3d>& points_cam,
                      RadialIntrinsics* model, double* squared_error) {
  const int num_points = static_cast<int>(x.size());
  const int num_unknowns = model->num_radial_terms + 1;
  if (model->num_radial_terms < 0 || model->num_radial_terms > 2 ||
      points_cam.size() != x.size() || num_points < num_unknowns) {
    return false;
  }
  Eigen::MatrixXd A(num_points, num_unknowns);
  Eigen::VectorXd b(num_points);
  for (int i = 0; i < num_points; ++i) {
    const double depth = points_cam[i].z() + model->tz;
    if (!(depth > 0)) {
      return false;
    }
    const double s = SignedRadialCoordinate(x[i], points_cam[i]);
    // An odd function of s, so that a point on the wrong half-line (s < 0)
    // predicts a negative radius and a large residual.
    const double phi = model->profile == RadialProfile::kPolynomial
                           ? s / depth
                           : std::atan2(s, depth);
    double phi_power = phi;
    for (int j = 0; j < num_unknowns; ++j) {
      A(i, j) = phi_power;
      phi_power *= phi * phi;
    }
    b(i) = x[i].norm();
  }
  Eigen::VectorXd beta;
  if (!SolveEquilibratedLeastSquares(A, b, &beta) || !(beta(0) > 0)) {
    return false;
  }
  model->focal = beta(0);
  model->k[0] = model->k[1] = 0;
  for (int j = 1; j < num_unknowns; ++j) {
    model->k[j - 1] = beta(j) / beta(0);
  }
  *squared_error = (A * beta - b).squaredNorm();
  return std::isfinite(*squared_error);
}

std::vector<RadialIntrinsics> EstimateRadialIntrinsics(
    const std::vector<Eigen::Vector2d>& x,
    const std::vector<Eigen::Vector3d>& points_cam,
    const RadialProfile profile, const int num_radial_terms) {
  std::vector<double> c(points_cam.size());
  for (size_t i = 0; i < points_cam.size(); ++i) {
    c[i] = points_cam[i].z();
  }
  // Every point must stay in front of the camera: tz > tz_bound = -min(c),
  // and u = tz - tz_bound is the depth of the nearest point. The division
  // model can be far from a wide-angle lens, so the grid spans a factor
  // kGridRange either side of its u, log-spaced, as depths are positive.
  // Without a usable division solution (a pinhole fit of a fisheye sample
  // may need f < 0), u is set to the spread median(c) - min(c), which does
  // not depend on tz.
  const double tz_bound = -*std::min_element(c.begin(), c.end());
  const double depth_spread = Median(c) + tz_bound;
  DivisionIntrinsics division;
  const double u0 =
      SolveDivisionIntrinsics(x, points_cam, num_radial_terms, &division) &&
              division.tz > tz_bound
          ? division.tz - tz_bound
          : depth_spread;
  if (!(u0 > 0) || !std::isfinite(u0)) {
    return {};
  }

  RadialIntrinsics model;
  model.profile = profile;
  model.num_radial_terms = num_radial_terms;
  std::vector<double> grid(kNumGridPoints);
  std::vector<double> errors(kNumGridPoints);
  for (int j = 0; j < kNumGridPoints; ++j) {
    const double exponent = 2.0 * j / (kNumGridPoints - 1) - 1;
    grid[j] = tz_bound + u0 * std::pow(kGridRange, exponent);
    errors[j] = ProfileError(x, points_cam, model, grid[j]);
  }

  // With a minimal sample every solution is a zero of E, so each local
  // minimum of the grid is refined before the solutions are ranked.
  std::vector<int> local_minima;
  for (int j = 0; j < kNumGridPoints; ++j) {
    if (std::isfinite(errors[j]) && (j == 0 || errors[j] <= errors[j - 1]) &&
        (j == kNumGridPoints - 1 || errors[j] <= errors[j + 1])) {
      local_minima.push_back(j);
    }
  }
  std::sort(local_minima.begin(), local_minima.end(),
            [&](int i, int j) { return errors[i] < errors[j]; });
  if (local_minima.size() > kMaxNumRefinedMinima) {
    local_minima.resize(kMaxNumRefinedMinima);
  }
  std::vector<std::pair<double, RadialIntrinsics>> candidates;
  for (const int j : local_minima) {
    const double lo = grid[std::max(j - 1, 0)];
    const double hi = grid[std::min(j + 1, kNumGridPoints - 1)];
    RadialIntrinsics candidate = model;
    candidate.tz = MinimizeProfileError(x, points_cam, model, lo, hi,
                                        kRelativeTzTolerance * (hi - lo));
    double squared_error = 0;
    if (FitRadialProfile(x, points_cam, &candidate, &squared_error)) {
      candidates.emplace_back(squared_error, candidate);
    }
  }
  std::stable_sort(
      candidates.begin(), candidates.end(),
      [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<RadialIntrinsics> models;
  for (const auto& candidate : candidates) {
    if (models.size() == kMaxNumCandidates) break;
    models.push_back(candidate.second);
  }
  return models;
}

void RadialIntrinsicsResiduals(const std::vector<Eigen::Vector2d>& x,
                               const std::vector<Eigen::Vector3d>& points_cam,
                               const RadialIntrinsics& model,
                               std::vector<double>* residuals) {
  residuals->resize(x.size());
  Eigen::Vector2d projection;
  for (size_t i = 0; i < x.size(); ++i) {
    (*residuals)[i] = model.Project(points_cam[i], &projection)
                          ? (projection - x[i]).squaredNorm()
                          : kInvalidResidual;
  }
}

}  // namespace rig_calibrator
