#include "src/solvers/intrinsics_solvers.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

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
// Brent's search stops when the minimum is known to within this fraction of
// its initial bracket.
constexpr double kRelativeTzTolerance = 1e-10;
constexpr int kMaxNumBrentIterations = 100;
// Smallest Cholesky pivot (a square root, so ~1e-14 in the eigenvalues) of
// the equilibrated normal equations of FitRadialProfile.
constexpr double kMinCholeskyPivot = 1e-7;

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

// FitRadialProfile with a fixed number of radial terms. The variable
// projection calls it hundreds of times per estimate: normal equations of at
// most 3 unknowns in fixed-size matrices, then the residuals in a second pass
// (no cancellation in the error).
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
  const auto basis = [&](const int i) {
    const double depth = points_cam[i].z() + model->tz;
    const double s = SignedRadialCoordinate(x[i], points_cam[i]);
    // An odd function of s, so that a point on the wrong half-line (s < 0)
    // predicts a negative radius and a large residual.
    const double phi = model->profile == RadialProfile::kPolynomial
                           ? s / depth
                           : std::atan2(s, depth);
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

// Whether r_d grows with the ray angle over the angles of the points:
// d r_d / d phi = f (1 + 3 k1 phi^2 + 5 k2 phi^4) > 0 for phi in [0, max_phi].
// A profile that folds back can fit points on the wrong half-line (a
// negative 1 + k1 phi^2 + k2 phi^4 mirrors them through the principal point)
// and is not a lens.
bool IsMonotonicOverPoints(const std::vector<Eigen::Vector2d>& x,
                           const std::vector<Eigen::Vector3d>& points_cam,
                           const RadialIntrinsics& model) {
  double max_phi = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    const double depth = points_cam[i].z() + model.tz;
    const double s = std::abs(SignedRadialCoordinate(x[i], points_cam[i]));
    max_phi = std::max(max_phi, model.profile == RadialProfile::kPolynomial
                                    ? s / depth
                                    : std::atan2(s, depth));
  }
  // g(t) = 1 + 3 k1 t + 5 k2 t^2 on t = phi^2 in [0, max_phi^2]: its minimum
  // is at an end or at the vertex.
  const double t_max = max_phi * max_phi;
  const auto g = [&](double t) {
    return 1 + 3 * model.k[0] * t + 5 * model.k[1] * t * t;
  };
  double min_g = std::min(g(0), g(t_max));
  if (model.k[1] != 0) {
    const double vertex = -3 * model.k[0] / (10 * model.k[1]);
    if (vertex > 0 && vertex < t_max) min_g = std::min(min_g, g(vertex));
  }
  return model.focal > 0 && min_g > 0;
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

// Brent's method (golden-section steps safeguarding parabolic interpolation)
// for the minimum of E over [lo, hi]. Stops when x is known to within
// kRelativeTzTolerance (hi - lo), or a few ulps of x.
double MinimizeProfileError(const std::vector<Eigen::Vector2d>& x,
                            const std::vector<Eigen::Vector3d>& points_cam,
                            const RadialIntrinsics& model, double lo,
                            double hi) {
  const auto E = [&](double tz) {
    return ProfileError(x, points_cam, model, tz);
  };
  const double golden = (3 - std::sqrt(5.0)) / 2;
  const double absolute_tolerance = kRelativeTzTolerance * (hi - lo);
  // Best, second best and previous second best points and their errors.
  double best = lo + golden * (hi - lo);
  double second = best;
  double third = best;
  double e_best = E(best);
  double e_second = e_best;
  double e_third = e_best;
  double step = 0;
  double previous_step = 0;
  for (int iteration = 0; iteration < kMaxNumBrentIterations; ++iteration) {
    const double middle = (lo + hi) / 2;
    const double tolerance =
        absolute_tolerance +
        4 * std::numeric_limits<double>::epsilon() * std::abs(best);
    if (std::abs(best - middle) <= 2 * tolerance - (hi - lo) / 2) {
      break;
    }
    bool parabolic = false;
    if (std::abs(previous_step) > tolerance) {
      // Vertex of the parabola through best, second and third.
      const double r = (best - second) * (e_best - e_third);
      double q = (best - third) * (e_best - e_second);
      double p = (best - third) * q - (best - second) * r;
      q = 2 * (q - r);
      if (q > 0) {
        p = -p;
      } else {
        q = -q;
      }
      if (std::abs(p) < std::abs(q * previous_step / 2) &&
          p > q * (lo - best) && p < q * (hi - best)) {
        previous_step = step;
        step = p / q;
        const double next = best + step;
        if (next - lo < 2 * tolerance || hi - next < 2 * tolerance) {
          step = best < middle ? tolerance : -tolerance;
        }
        parabolic = true;
      }
    }
    if (!parabolic) {
      previous_step = (best < middle ? hi : lo) - best;
      step = golden * previous_step;
    }
    const double next = best + (std::abs(step) >= tolerance
                                    ? step
                                    : (step > 0 ? tolerance : -tolerance));
    const double e_next = E(next);
    if (e_next <= e_best) {
      (next < best ? hi : lo) = best;
      third = second;
      e_third = e_second;
      second = best;
      e_second = e_best;
      best = next;
      e_best = e_next;
    } else {
      (next < best ? lo : hi) = next;
      if (e_next <= e_second || second == best) {
        third = second;
        e_third = e_second;
        second = next;
        e_second = e_next;
      } else if (e_next <= e_third || third == best || third == second) {
        third = next;
        e_third = e_next;
      }
    }
  }
  return best;
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

std::vector<RadialIntrinsics> EstimateRadialIntrinsics(
    const std::vector<Eigen::Vector2d>& x,
    const std::vector<Eigen::Vector3d>& points_cam, const RadialProfile profile,
    const int num_radial_terms) {
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
    candidate.tz = MinimizeProfileError(x, points_cam, model, lo, hi);
    double squared_error = 0;
    if (FitRadialProfile(x, points_cam, &candidate, &squared_error) &&
        IsMonotonicOverPoints(x, points_cam, candidate)) {
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
