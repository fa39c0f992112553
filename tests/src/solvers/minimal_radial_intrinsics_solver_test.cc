#include "src/solvers/minimal_radial_intrinsics_solver.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "src/solvers/radial_profile_fit.h"
#include "tests/src/solvers/radial_intrinsics_scene.h"

namespace rig_calibrator {
namespace {

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
// true profile grows over the sample.
struct Instance {
  RadialIntrinsics truth;
  RadialIntrinsicsScene scene;
  double mean_depth = 0;
};

Instance MakeInstance(const RadialProfile profile, const int num_terms,
                      const unsigned seed) {
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
    for (int i = 0; i < num_terms + 2; ++i) {
      const double angle = in(1 * kPi / 180, max_angle);
      const double depth = in(1, 30);
      max_phi = std::max(max_phi, polynomial ? std::tan(angle) : angle);
      instance.mean_depth += depth / (num_terms + 2);
      AddPoint(instance.truth, angle, in(0, 2 * kPi), depth, &instance.scene);
    }
    if (GrowsUpTo(instance.truth, max_phi)) return instance;
  }
}

struct Case {
  RadialProfile profile;
  int num_terms;
  size_t max_num_solutions;  // the degree n^2 + 3n + 1 (polynomial)
};

std::string CaseName(const Case& c) {
  return std::string(c.profile == RadialProfile::kPolynomial ? "polynomial"
                                                             : "equidistant") +
         " with " + std::to_string(c.num_terms) + " terms";
}

// Every random exact minimal instance: the truth is among the solutions to
// 1e-8, and every solution reproduces the sample exactly (a solver that adds
// non-solutions fails), are in increasing tz, and within the degree bound.
void ExpectEveryInstanceSolved(const Case& c) {
  SCOPED_TRACE(CaseName(c));
  int num_recovered = 0;
  double max_error = 0;
  size_t max_num_solutions = 0;
  for (int seed = 0; seed < kNumInstances; ++seed) {
    const Instance instance = MakeInstance(c.profile, c.num_terms, seed);
    const std::vector<RadialIntrinsics> solutions =
        SolveMinimalRadialIntrinsics(instance.scene.x,
                                     instance.scene.points_cam, c.profile,
                                     c.num_terms, std::nullopt);
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

// The solutions found independently of the solver: every sign change of
// det M(tz), with M's rows [phi_i, phi_i^3, .., -rho_i] computed directly,
// on a scan 16 times finer than the solver's (the depth of the nearest point
// from 1e-4 to 1e4 times the largest |s|, log-spaced), refined by bisection;
// kept if the linear fit at that tz has f > 0 and a growing profile.
std::vector<double> BruteForceSolutionTzs(const Instance& instance,
                                          const RadialProfile profile,
                                          const int num_terms) {
  const RadialIntrinsicsScene& scene = instance.scene;
  const int size = num_terms + 2;
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
      for (int j = 0; j <= num_terms; ++j) M(i, j) = std::pow(phi, 2 * j + 1);
      M(i, size - 1) = -scene.x[i].norm();
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
    if (FitRadialProfile(scene.x, scene.points_cam, std::nullopt, &model,
                         &squared_error) &&
        RadiusGrowsOverPoints(scene.x, scene.points_cam, model)) {
      tzs.push_back(model.tz);
    }
  }
  return tzs;
}

// Every solution that the brute-force scan finds is returned (a solver that
// finds the truth but drops other solutions fails), on 100 instances per
// case.
TEST(SolveMinimalRadialIntrinsics, FindsEverySolution) {
  int num_solutions = 0;
  for (const RadialProfile profile :
       {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
    for (int num_terms = 0; num_terms <= 2; ++num_terms) {
      for (int seed = 0; seed < 100; ++seed) {
        const Instance instance = MakeInstance(profile, num_terms, seed);
        const std::vector<RadialIntrinsics> solutions =
            SolveMinimalRadialIntrinsics(instance.scene.x,
                                         instance.scene.points_cam, profile,
                                         num_terms, std::nullopt);
        for (const double tz :
             BruteForceSolutionTzs(instance, profile, num_terms)) {
          ++num_solutions;
          double closest = std::numeric_limits<double>::infinity();
          for (const RadialIntrinsics& solution : solutions) {
            closest = std::min(closest, std::abs(solution.tz - tz));
          }
          EXPECT_LT(closest, 1e-6 * instance.mean_depth)
              << CaseName({profile, num_terms, 0}) << " seed " << seed << " tz "
              << tz;
        }
      }
    }
  }
  std::cout << num_solutions << " solutions found by the scan\n";
}

// Points on the wrong half-line of the radial pose (s < 0) fit only
// profiles with f < 0 or a radial factor that turns negative, which mirror
// the points through the principal point: no solution. The same samples on
// the right half-line are solved.
TEST(SolveMinimalRadialIntrinsics, RejectsMirroringProfiles) {
  for (const RadialProfile profile :
       {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
    for (int num_terms = 0; num_terms <= 2; ++num_terms) {
      for (int seed = 0; seed < 50; ++seed) {
        Instance instance = MakeInstance(profile, num_terms, seed);
        EXPECT_FALSE(SolveMinimalRadialIntrinsics(
                         instance.scene.x, instance.scene.points_cam, profile,
                         num_terms, std::nullopt)
                         .empty());
        for (Eigen::Vector3d& point : instance.scene.points_cam) {
          point.head<2>() *= -1;
        }
        EXPECT_TRUE(SolveMinimalRadialIntrinsics(
                        instance.scene.x, instance.scene.points_cam, profile,
                        num_terms, std::nullopt)
                        .empty())
            << CaseName({profile, num_terms, 0}) << " seed " << seed;
      }
    }
  }
}

TEST(SolveMinimalRadialIntrinsics, RejectsBadInput) {
  const Instance instance = MakeInstance(RadialProfile::kPolynomial, 2, 1);
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

}  // namespace
}  // namespace rig_calibrator
