#include "src/solvers/minimal_radial_intrinsics_solver.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "src/solvers/radial_profile_fit.h"
#include "tests/src/solvers/radial_intrinsics_scene.h"

namespace rig_calibrator {
namespace minimal_radial_intrinsics_solver_test {

using testing::AddPoint;
using testing::kPi;
using testing::MakeRadialIntrinsics;
using testing::RadialIntrinsicsScene;
using testing::RelativeError;

constexpr int kNumInstances = 1000;
// Required accuracy of the true solution among the returned ones.
constexpr double kMaxRelativeError = 1e-8;

// Whether r_d = f phi (1 + k1 phi^2 + k2 phi^4) grows on [0, max_phi],
// checked on a dense sampling (independent of RadiusGrowsOverPoints).
bool GrowsUpTo(const RadialIntrinsics& model, const double max_phi) {
  for (int i = 0; i <= 1000; ++i) {
    const double phi = max_phi * i / 1000;
    if (!(1 + 3 * model.k[0] * phi * phi + 5 * model.k[1] * std::pow(phi, 4) >
          0.05)) {
      return false;
    }
  }
  return true;
}

// A random minimal instance over realistic geometry: focal 300-1500 px,
// tz in [-2, 2] m, depths c + tz of 1-30 m, rays up to 60 degrees
// (polynomial) or 85 degrees (equidistant) off the axis, distortion k1, k2
// up to 0.4, 0.1 (polynomial) or 0.1, 0.02 (equidistant), redrawn until the
// true profile grows over the sample; n + 2 points, n + 1 for the solver with
// the focal length known.
struct Instance {
  RadialIntrinsics truth;
  RadialIntrinsicsScene scene;
  double mean_depth = 0;
};

Instance MakeInstance(const RadialProfile profile, const int num_terms,
                      const bool known_focal, const unsigned seed) {
  const int num_points = num_terms + (known_focal ? 1 : 2);
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> uniform(0, 1);
  const auto in = [&](double lo, double hi) {
    return lo + (hi - lo) * uniform(generator);
  };
  const bool polynomial = profile == RadialProfile::kPolynomial;
  const double max_angle = (polynomial ? 60 : 85) * kPi / 180;
  while (true) {
    Instance instance;
    instance.truth =
        MakeRadialIntrinsics(profile, num_terms, in(-2, 2), in(300, 1500),
                             polynomial ? in(-0.4, 0.2) : in(-0.1, 0.1),
                             polynomial ? in(-0.1, 0.1) : in(-0.02, 0.02));
    double max_phi = 0;
    for (int i = 0; i < num_points; ++i) {
      const double angle = in(1 * kPi / 180, max_angle);
      const double depth = in(1, 30);
      max_phi = std::max(max_phi, polynomial ? std::tan(angle) : angle);
      instance.mean_depth += depth / num_points;
      AddPoint(instance.truth, angle, in(0, 2 * kPi), depth, &instance.scene);
    }
    if (GrowsUpTo(instance.truth, max_phi)) return instance;
  }
}

struct Case {
  RadialProfile profile;
  int num_terms;
  // The degree n^2 + 3n + 1, or n^2 + n + 1 with f known (polynomial).
  size_t max_num_solutions;
  bool known_focal = false;  // the solver is given the true f
};

std::string CaseName(const Case& c) {
  return std::string(c.profile == RadialProfile::kPolynomial ? "polynomial"
                                                             : "equidistant") +
         " with " + std::to_string(c.num_terms) + " terms" +
         (c.known_focal ? ", f known" : "");
}

std::optional<double> KnownFocal(const bool known_focal,
                                 const Instance& instance) {
  return known_focal ? std::optional<double>(instance.truth.focal)
                     : std::nullopt;
}

// Every random exact minimal instance: the truth is among the solutions to
// 1e-8, and every solution reproduces the sample exactly (a solver that adds
// non-solutions fails), are in increasing tz, and within the degree bound;
// with f known every solution has exactly that f.
void ExpectEveryInstanceSolved(const Case& c) {
  SCOPED_TRACE(CaseName(c));
  int num_recovered = 0;
  double max_error = 0;
  size_t max_num_solutions = 0;
  for (int seed = 0; seed < kNumInstances; ++seed) {
    const Instance instance =
        MakeInstance(c.profile, c.num_terms, c.known_focal, seed);
    const std::vector<RadialIntrinsics> solutions =
        SolveMinimalRadialIntrinsics(
            instance.scene.x, instance.scene.points_cam, c.profile, c.num_terms,
            KnownFocal(c.known_focal, instance));
    EXPECT_LE(solutions.size(), c.max_num_solutions) << "seed " << seed;
    max_num_solutions = std::max(max_num_solutions, solutions.size());
    double best_error = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < solutions.size(); ++i) {
      best_error = std::min(
          best_error,
          RelativeError(solutions[i], instance.truth, instance.mean_depth));
      if (i > 0) {
        EXPECT_GT(solutions[i].tz, solutions[i - 1].tz);
      }
      EXPECT_EQ(solutions[i].profile, c.profile);
      EXPECT_EQ(solutions[i].num_radial_terms, c.num_terms);
      if (c.known_focal) {
        EXPECT_EQ(solutions[i].focal, instance.truth.focal);
      }
      for (size_t j = 0; j < instance.scene.x.size(); ++j) {
        Eigen::Vector2d projection;
        ASSERT_TRUE(
            solutions[i].Project(instance.scene.points_cam[j], &projection));
        EXPECT_LT((projection - instance.scene.x[j]).norm(),
                  1e-6 * instance.scene.x[j].norm())
            << "seed " << seed << " solution " << i;
      }
    }
    EXPECT_LE(best_error, kMaxRelativeError) << "seed " << seed;
    num_recovered += best_error <= kMaxRelativeError;
    if (std::isfinite(best_error)) max_error = std::max(max_error, best_error);
  }
  EXPECT_EQ(num_recovered, kNumInstances);
  std::cout << CaseName(c) << ": " << num_recovered << "/" << kNumInstances
            << " recovered, max relative error " << max_error << ", at most "
            << max_num_solutions << " solutions\n";
}

TEST(SolveMinimalRadialIntrinsics, PolynomialEveryExactInstance) {
  for (const Case c : {Case{RadialProfile::kPolynomial, 0, 1},
                       Case{RadialProfile::kPolynomial, 1, 5},
                       Case{RadialProfile::kPolynomial, 2, 11}}) {
    ExpectEveryInstanceSolved(c);
  }
}

TEST(SolveMinimalRadialIntrinsics, EquidistantEveryExactInstance) {
  for (const Case c : {Case{RadialProfile::kEquidistant, 0, 11},
                       Case{RadialProfile::kEquidistant, 1, 11},
                       Case{RadialProfile::kEquidistant, 2, 11}}) {
    ExpectEveryInstanceSolved(c);
  }
}

// With the true f given, n + 1 points: the truth to 1e-8 among at most the
// polynomial degree n^2 + n + 1 (1, 3, 7) solutions.
TEST(SolveMinimalRadialIntrinsics, KnownFocalEveryExactInstance) {
  for (const Case c : {Case{RadialProfile::kPolynomial, 0, 1, true},
                       Case{RadialProfile::kPolynomial, 1, 3, true},
                       Case{RadialProfile::kPolynomial, 2, 7, true},
                       Case{RadialProfile::kEquidistant, 0, 7, true},
                       Case{RadialProfile::kEquidistant, 1, 7, true},
                       Case{RadialProfile::kEquidistant, 2, 7, true}}) {
    ExpectEveryInstanceSolved(c);
  }
}

// The solutions found independently of the solver: every sign change of
// det M(tz), with M's rows [phi_i, phi_i^3, .., -rho_i] (with f known
// [phi_i^3, .., f phi_i - rho_i]) computed directly, on a scan 16 times finer
// than the solver's (the depth of the nearest point from 1e-4 to 1e4 times
// the largest |s|, log-spaced), refined by bisection; kept if the linear fit
// at that tz has f > 0 and a growing profile.
std::vector<double> BruteForceSolutionTzs(
    const Instance& instance, const RadialProfile profile, const int num_terms,
    const std::optional<double>& known_focal) {
  const RadialIntrinsicsScene& scene = instance.scene;
  const int size = static_cast<int>(scene.x.size());
  const int first_term = known_focal ? 1 : 0;
  double min_c = std::numeric_limits<double>::infinity(), max_s = 0;
  for (const Eigen::Vector3d& point : scene.points_cam) {
    min_c = std::min(min_c, point.z());
    max_s = std::max(max_s, point.head<2>().norm());
  }
  const auto det = [&](const double tz) {
    Eigen::MatrixXd M(size, size);
    for (int i = 0; i < size; ++i) {
      const double phi = ProfileAngle(
          profile, SignedRadialCoordinate(scene.x[i], scene.points_cam[i]),
          scene.points_cam[i].z() + tz);
      for (int j = first_term; j <= num_terms; ++j) {
        M(i, j - first_term) = std::pow(phi, 2 * j + 1);
      }
      M(i, size - 1) =
          (known_focal ? *known_focal * phi : 0.0) - scene.x[i].norm();
    }
    return M.determinant();
  };
  const auto tz_of = [&](const double u) {
    return -min_c + max_s * std::exp(u);
  };
  constexpr int kNumSteps = 4096;
  std::vector<double> tzs;
  for (int k = 0; k < kNumSteps; ++k) {
    double lo = 9.2 * (2.0 * k / kNumSteps - 1);
    double hi = 9.2 * (2.0 * (k + 1) / kNumSteps - 1);
    const bool lo_negative = det(tz_of(lo)) < 0;
    if (lo_negative == (det(tz_of(hi)) < 0)) continue;
    for (int iteration = 0; iteration < 100; ++iteration) {
      const double middle = (lo + hi) / 2;
      ((det(tz_of(middle)) < 0) == lo_negative ? lo : hi) = middle;
    }
    RadialIntrinsics model;
    model.profile = profile;
    model.num_radial_terms = num_terms;
    model.tz = tz_of((lo + hi) / 2);
    double squared_error = 0;
    if (FitRadialProfile(scene.x, scene.points_cam, known_focal, &model,
                         &squared_error) &&
        RadiusGrowsOverPoints(scene.x, scene.points_cam, model)) {
      tzs.push_back(model.tz);
    }
  }
  return tzs;
}

// Every solution that the brute-force scan finds is returned (a solver that
// finds the truth but drops other solutions fails), on 100 instances per
// case, with f free and known.
TEST(SolveMinimalRadialIntrinsics, FindsEverySolution) {
  for (const bool known_focal : {false, true}) {
    int num_solutions = 0;
    for (const RadialProfile profile :
         {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
      for (int num_terms = 0; num_terms <= 2; ++num_terms) {
        const Case c{profile, num_terms, 0, known_focal};
        for (int seed = 0; seed < 100; ++seed) {
          const Instance instance =
              MakeInstance(profile, num_terms, known_focal, seed);
          const std::optional<double> focal = KnownFocal(known_focal, instance);
          const std::vector<RadialIntrinsics> solutions =
              SolveMinimalRadialIntrinsics(instance.scene.x,
                                           instance.scene.points_cam, profile,
                                           num_terms, focal);
          for (const double tz :
               BruteForceSolutionTzs(instance, profile, num_terms, focal)) {
            ++num_solutions;
            double closest = std::numeric_limits<double>::infinity();
            for (const RadialIntrinsics& solution : solutions) {
              closest = std::min(closest, std::abs(solution.tz - tz));
            }
            EXPECT_LT(closest, 1e-6 * instance.mean_depth)
                << CaseName(c) << " seed " << seed << " tz " << tz;
          }
        }
      }
    }
    std::cout << num_solutions << " solutions found by the scan"
              << (known_focal ? " with f known" : "") << "\n";
  }
}

// Points on the wrong half-line of the radial pose (s < 0) fit only
// profiles with f < 0 or a radial factor that turns negative, which mirror
// the points through the principal point: no solution, with f free or known.
// The same samples on the right half-line are solved.
TEST(SolveMinimalRadialIntrinsics, RejectsMirroringProfiles) {
  for (const bool known_focal : {false, true}) {
    for (const RadialProfile profile :
         {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
      for (int num_terms = 0; num_terms <= 2; ++num_terms) {
        for (int seed = 0; seed < 50; ++seed) {
          Instance instance =
              MakeInstance(profile, num_terms, known_focal, seed);
          const std::optional<double> focal = KnownFocal(known_focal, instance);
          EXPECT_FALSE(SolveMinimalRadialIntrinsics(instance.scene.x,
                                                    instance.scene.points_cam,
                                                    profile, num_terms, focal)
                           .empty());
          for (Eigen::Vector3d& point : instance.scene.points_cam) {
            point.head<2>() *= -1;
          }
          EXPECT_TRUE(SolveMinimalRadialIntrinsics(instance.scene.x,
                                                   instance.scene.points_cam,
                                                   profile, num_terms, focal)
                          .empty())
              << CaseName({profile, num_terms, 0, known_focal}) << " seed "
              << seed;
        }
      }
    }
  }
}

TEST(SolveMinimalRadialIntrinsics, RejectsBadInput) {
  const Instance instance =
      MakeInstance(RadialProfile::kPolynomial, 2, false, 1);
  const std::vector<Eigen::Vector2d>& x = instance.scene.x;
  const std::vector<Eigen::Vector3d>& points_cam = instance.scene.points_cam;
  // Not the minimal number of points for the number of terms.
  EXPECT_TRUE(SolveMinimalRadialIntrinsics(
                  x, points_cam, RadialProfile::kPolynomial, 1, std::nullopt)
                  .empty());
  EXPECT_TRUE(SolveMinimalRadialIntrinsics(
                  x, points_cam, RadialProfile::kPolynomial, 3, std::nullopt)
                  .empty());
  EXPECT_TRUE(SolveMinimalRadialIntrinsics(
                  x, {points_cam.begin(), points_cam.end() - 1},
                  RadialProfile::kPolynomial, 2, std::nullopt)
                  .empty());
  // Non-finite values and every pixel on the principal point.
  std::vector<Eigen::Vector3d> not_finite = points_cam;
  not_finite[2].z() = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Eigen::Vector2d> centered(4, Eigen::Vector2d::Zero());
  for (const RadialProfile profile :
       {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
    EXPECT_TRUE(
        SolveMinimalRadialIntrinsics(x, not_finite, profile, 2, std::nullopt)
            .empty());
    EXPECT_TRUE(SolveMinimalRadialIntrinsics(centered, points_cam, profile, 2,
                                             std::nullopt)
                    .empty());
  }
}

// With f known: n + 2 points (the sample of the free-f solver) or n are not
// minimal; a known f that is not finite and positive, pixels on the principal
// point, points on the optical axis (s = 0: no radial information, the
// polynomial n = 0 root tz = f s / rho - c puts the point on the camera
// plane) and non-finite values give no solution.
TEST(SolveMinimalRadialIntrinsics, KnownFocalRejectsDegenerateSamples) {
  for (const RadialProfile profile :
       {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
    for (int num_terms = 0; num_terms <= 2; ++num_terms) {
      SCOPED_TRACE(CaseName({profile, num_terms, 0, true}));
      const Instance instance = MakeInstance(profile, num_terms, true, 3);
      const std::vector<Eigen::Vector2d>& x = instance.scene.x;
      const std::vector<Eigen::Vector3d>& points_cam =
          instance.scene.points_cam;
      const double focal = instance.truth.focal;
      ASSERT_FALSE(
          SolveMinimalRadialIntrinsics(x, points_cam, profile, num_terms, focal)
              .empty());
      const Instance larger = MakeInstance(profile, num_terms, false, 3);
      EXPECT_TRUE(SolveMinimalRadialIntrinsics(larger.scene.x,
                                               larger.scene.points_cam, profile,
                                               num_terms, focal)
                      .empty());
      EXPECT_TRUE(SolveMinimalRadialIntrinsics(
                      {x.begin(), x.end() - 1},
                      {points_cam.begin(), points_cam.end() - 1}, profile,
                      num_terms, focal)
                      .empty());
      for (const double bad_focal :
           {0.0, -focal, std::numeric_limits<double>::quiet_NaN(),
            std::numeric_limits<double>::infinity()}) {
        EXPECT_TRUE(SolveMinimalRadialIntrinsics(x, points_cam, profile,
                                                 num_terms, bad_focal)
                        .empty());
      }
      const std::vector<Eigen::Vector2d> centered(x.size(),
                                                  Eigen::Vector2d::Zero());
      EXPECT_TRUE(SolveMinimalRadialIntrinsics(centered, points_cam, profile,
                                               num_terms, focal)
                      .empty());
      std::vector<Eigen::Vector3d> on_axis = points_cam;
      for (Eigen::Vector3d& point : on_axis) point.head<2>().setZero();
      EXPECT_TRUE(
          SolveMinimalRadialIntrinsics(x, on_axis, profile, num_terms, focal)
              .empty());
      std::vector<Eigen::Vector3d> not_finite = points_cam;
      not_finite.back().z() = std::numeric_limits<double>::quiet_NaN();
      EXPECT_TRUE(
          SolveMinimalRadialIntrinsics(x, not_finite, profile, num_terms, focal)
              .empty());
    }
  }
}

}  // namespace minimal_radial_intrinsics_solver_test
}  // namespace rig_calibrator
