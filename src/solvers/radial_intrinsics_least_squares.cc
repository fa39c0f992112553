#include "src/solvers/radial_intrinsics_least_squares.h"

#include <colmap/util/math.h>

#include <algorithm>
#include <boost/math/tools/minima.hpp>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "src/solvers/division_intrinsics_solver.h"
#include "src/solvers/radial_profile_fit.h"

namespace rig_calibrator {
namespace {

// Log-spaced grid over the depth of the nearest point: kNumGridPoints from
// 1/kGridRange to kGridRange times the division model's value (a factor 1.15
// between neighbours).
constexpr int kNumGridPoints = 49;
constexpr double kGridRange = 30;
// Local minima of the grid refined, and solutions returned.
constexpr size_t kMaxNumRefinedMinima = 5;
constexpr size_t kMaxNumCandidates = 3;
// Brent's method on the grid exponent: Boost's precision limit for a
// minimum, half the mantissa bits.
constexpr int kBrentBits = std::numeric_limits<double>::digits / 2;
constexpr std::uintmax_t kMaxNumBrentIterations = 100;
// Gauss-Newton steps after Brent (2-3 reach machine precision on exact data).
constexpr int kMaxNumGaussNewtonPolishIterations = 5;

// E(tz) of the variable projection; infinite where FitRadialProfile fails.
double ProfileError(const std::vector<Eigen::Vector2d>& x,
                    const std::vector<Eigen::Vector3d>& points_cam,
                    const std::optional<double>& known_focal,
                    RadialIntrinsics model, const double tz) {
  model.tz = tz;
  double squared_error = 0;
  if (!FitRadialProfile(x, points_cam, known_focal, &model, &squared_error)) {
    return std::numeric_limits<double>::infinity();
  }
  return squared_error;
}

// The grid's reference depth of the nearest point, u0 = tz0 + min(c), from the
// division model; 0 if there is none. The division model can be far from a
// wide-angle lens, hence the wide grid around it. Without a usable division
// solution (a pinhole fit of a fisheye sample may need f < 0), u0 is the
// spread median(c) - min(c), which does not depend on tz.
double ReferenceNearestDepth(const std::vector<Eigen::Vector2d>& x,
                             const std::vector<Eigen::Vector3d>& points_cam,
                             const int num_radial_terms,
                             const double tz_bound) {
  std::vector<double> c(points_cam.size());
  for (size_t i = 0; i < points_cam.size(); ++i) {
    c[i] = points_cam[i].z();
  }
  DivisionIntrinsics division;
  const double u0 =
      SolveDivisionIntrinsics(x, points_cam, num_radial_terms, &division) &&
              division.tz > tz_bound
          ? division.tz - tz_bound
          : colmap::Median(c) + tz_bound;
  return u0 > 0 && std::isfinite(u0) ? u0 : 0;
}

}  // namespace

std::vector<RadialIntrinsics> SolveRadialIntrinsicsLeastSquares(
    const std::vector<Eigen::Vector2d>& x,
    const std::vector<Eigen::Vector3d>& points_cam, const RadialProfile profile,
    const int num_radial_terms, const std::optional<double>& known_focal) {
  if (x.empty() || x.size() != points_cam.size()) {
    return {};
  }
  // Every point must stay in front of the camera: tz > tz_bound = -min(c),
  // and tz - tz_bound is the depth of the nearest point; it is log-spaced on
  // the grid, tz(e) = tz_bound + u0 kGridRange^e for e in [-1, 1].
  double tz_bound = -std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& point : points_cam) {
    tz_bound = std::max(tz_bound, -point.z());
  }
  const double u0 =
      ReferenceNearestDepth(x, points_cam, num_radial_terms, tz_bound);
  if (!(u0 > 0)) {
    return {};
  }
  RadialIntrinsics model;
  model.profile = profile;
  model.num_radial_terms = num_radial_terms;
  const auto tz_of_exponent = [&](const double exponent) {
    return tz_bound + u0 * std::pow(kGridRange, exponent);
  };
  const auto E = [&](const double exponent) {
    return ProfileError(x, points_cam, known_focal, model,
                        tz_of_exponent(exponent));
  };
  std::vector<double> exponents(kNumGridPoints);
  std::vector<double> errors(kNumGridPoints);
  for (int j = 0; j < kNumGridPoints; ++j) {
    exponents[j] = 2.0 * j / (kNumGridPoints - 1) - 1;
    errors[j] = E(exponents[j]);
  }

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
    std::uintmax_t max_num_iterations = kMaxNumBrentIterations;
    const double exponent = boost::math::tools::brent_find_minima(
                                E, exponents[std::max(j - 1, 0)],
                                exponents[std::min(j + 1, kNumGridPoints - 1)],
                                kBrentBits, max_num_iterations)
                                .first;
    RadialIntrinsics candidate = model;
    candidate.tz = tz_of_exponent(exponent);
    double squared_error = 0;
    if (RefineRadialProfileAndTz(x, points_cam, known_focal,
                                 kMaxNumGaussNewtonPolishIterations, &candidate,
                                 &squared_error) &&
        RadiusGrowsOverPoints(x, points_cam, candidate)) {
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

}  // namespace rig_calibrator
