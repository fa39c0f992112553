#include "src/solvers/radial_intrinsics_least_squares.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <optional>
#include <vector>

#include "tests/src/solvers/radial_intrinsics_scene.h"

namespace rig_calibrator {
namespace radial_intrinsics_least_squares_test {

using testing::MakeRadialIntrinsics;
using testing::MakeRadialIntrinsicsScene;
using testing::RadialIntrinsicsScene;
using testing::RelativeError;

RadialIntrinsics Truth(const RadialProfile profile, const int num_terms) {
  return profile == RadialProfile::kPolynomial
             ? MakeRadialIntrinsics(profile, num_terms, -0.6, 500, -0.3, 0.08)
             : MakeRadialIntrinsics(profile, num_terms, -0.6, 300, 0.03,
                                    -0.005);
}

// Within 45 degrees r_d = f q (1 - 0.3 q^2 + 0.08 q^4) still grows with q.
double MaxAngleDeg(const RadialProfile profile) {
  return profile == RadialProfile::kPolynomial ? 45 : 75;
}

// Exact data of each profile and number of terms, with f estimated and with
// the true f given: the first solution is the truth to 1e-8 (a given f bit
// for bit in every solution).
TEST(SolveRadialIntrinsicsLeastSquares, ExactData) {
  for (const bool focal_known : {false, true}) {
    for (const RadialProfile profile :
         {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
      for (int num_terms = 0; num_terms <= 2; ++num_terms) {
        SCOPED_TRACE(100 * focal_known + 10 * static_cast<int>(profile) +
                     num_terms);
        const RadialIntrinsics truth = Truth(profile, num_terms);
        const RadialIntrinsicsScene scene =
            MakeRadialIntrinsicsScene(truth, 200, MaxAngleDeg(profile), 20);
        const std::vector<RadialIntrinsics> models =
            SolveRadialIntrinsicsLeastSquares(
                scene.x, scene.points_cam, profile, num_terms,
                focal_known ? std::optional<double>(truth.focal)
                            : std::nullopt);
        ASSERT_FALSE(models.empty());
        EXPECT_LE(models.size(), 3);
        EXPECT_LT(RelativeError(models[0], truth, 1), 1e-8);
        EXPECT_EQ(models[0].profile, profile);
        EXPECT_EQ(models[0].num_radial_terms, num_terms);
        for (const RadialIntrinsics& model : models) {
          if (focal_known) EXPECT_EQ(model.focal, truth.focal);
        }
      }
    }
  }
}

// 0.5 px noise on 500 points (no outliers: this is the local estimator on
// inliers), with f estimated and with the true f given (then f exact).
// Measured: focal <= 0.03 %, tz <= 0.7 mm (0.93 mm with f given), k <=
// 0.0016 (printed).
TEST(SolveRadialIntrinsicsLeastSquares, NoisyData) {
  for (const bool focal_known : {false, true}) {
    for (const RadialProfile profile :
         {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
      SCOPED_TRACE(10 * focal_known + static_cast<int>(profile));
      const RadialIntrinsics truth = Truth(profile, 2);
      RadialIntrinsicsScene scene =
          MakeRadialIntrinsicsScene(truth, 500, MaxAngleDeg(profile), 7);
      testing::AddNoiseAndOutliers(0.5, 0, 8, &scene);
      const std::vector<RadialIntrinsics> models =
          SolveRadialIntrinsicsLeastSquares(
              scene.x, scene.points_cam, profile, 2,
              focal_known ? std::optional<double>(truth.focal) : std::nullopt);
      ASSERT_FALSE(models.empty());
      if (focal_known) {
        EXPECT_EQ(models[0].focal, truth.focal);
      } else {
        EXPECT_NEAR(models[0].focal, truth.focal, 0.001 * truth.focal);
      }
      EXPECT_NEAR(models[0].tz, truth.tz, 0.002);
      EXPECT_NEAR(models[0].k[0], truth.k[0], 0.005);
      EXPECT_NEAR(models[0].k[1], truth.k[1], 0.005);
      std::cout << (profile == RadialProfile::kPolynomial ? "polynomial"
                                                          : "equidistant")
                << (focal_known ? " f known" : " f estimated")
                << ": |tz error| " << std::abs(models[0].tz - truth.tz)
                << " m, |k1 error| " << std::abs(models[0].k[0] - truth.k[0])
                << ", |k2 error| " << std::abs(models[0].k[1] - truth.k[1])
                << "\n";
    }
  }
}

// Points on the wrong half-line fit only mirroring profiles: none returned.
TEST(SolveRadialIntrinsicsLeastSquares, RejectsMirroringProfiles) {
  const RadialIntrinsics truth = Truth(RadialProfile::kPolynomial, 2);
  RadialIntrinsicsScene scene = MakeRadialIntrinsicsScene(truth, 50, 45, 9);
  for (Eigen::Vector3d& point : scene.points_cam) {
    point.head<2>() *= -1;
  }
  EXPECT_TRUE(SolveRadialIntrinsicsLeastSquares(scene.x, scene.points_cam,
                                                RadialProfile::kPolynomial, 2,
                                                std::nullopt)
                  .empty());
  EXPECT_TRUE(SolveRadialIntrinsicsLeastSquares(
                  {}, {}, RadialProfile::kPolynomial, 2, std::nullopt)
                  .empty());
}

}  // namespace radial_intrinsics_least_squares_test
}  // namespace rig_calibrator
