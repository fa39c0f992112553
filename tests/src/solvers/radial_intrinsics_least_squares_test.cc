#include "src/solvers/radial_intrinsics_least_squares.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <vector>

#include "tests/src/solvers/radial_intrinsics_scene.h"

namespace rig_calibrator {
namespace {

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

// Exact data of each profile and number of terms: the first solution is the
// truth.
TEST(SolveRadialIntrinsicsLeastSquares, ExactData) {
  for (const RadialProfile profile :
       {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
    for (int num_terms = 0; num_terms <= 2; ++num_terms) {
      SCOPED_TRACE(10 * static_cast<int>(profile) + num_terms);
      const RadialIntrinsics truth = Truth(profile, num_terms);
      const RadialIntrinsicsScene scene =
          MakeRadialIntrinsicsScene(truth, 200, MaxAngleDeg(profile), 20);
      const std::vector<RadialIntrinsics> models =
          SolveRadialIntrinsicsLeastSquares(scene.x, scene.points_cam, profile,
                                            num_terms, std::nullopt);
      ASSERT_FALSE(models.empty());
      EXPECT_LE(models.size(), 3);
      EXPECT_LT(RelativeError(models[0], truth, 1), 1e-8);
      EXPECT_EQ(models[0].profile, profile);
      EXPECT_EQ(models[0].num_radial_terms, num_terms);
    }
  }
}

// 0.5 px noise on 500 points (no outliers: this is the local estimator on
// inliers). Measured: focal <= 0.03 %, tz <= 0.7 mm, k <= 0.0016.
TEST(SolveRadialIntrinsicsLeastSquares, NoisyData) {
  for (const RadialProfile profile :
       {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
    SCOPED_TRACE(static_cast<int>(profile));
    const RadialIntrinsics truth = Truth(profile, 2);
    RadialIntrinsicsScene scene =
        MakeRadialIntrinsicsScene(truth, 500, MaxAngleDeg(profile), 7);
    testing::AddNoiseAndOutliers(0.5, 0, 8, &scene);
    const std::vector<RadialIntrinsics> models =
        SolveRadialIntrinsicsLeastSquares(scene.x, scene.points_cam, profile, 2,
                                          std::nullopt);
    ASSERT_FALSE(models.empty());
    EXPECT_NEAR(models[0].focal, truth.focal, 0.001 * truth.focal);
    EXPECT_NEAR(models[0].tz, truth.tz, 0.002);
    EXPECT_NEAR(models[0].k[0], truth.k[0], 0.005);
    EXPECT_NEAR(models[0].k[1], truth.k[1], 0.005);
  }
}

// With the true f given, exact data of each profile and number of terms: the
// first solution is the truth to 1e-8 with f the given value bit for bit.
TEST(SolveRadialIntrinsicsLeastSquares, KnownFocalExactData) {
  for (const RadialProfile profile :
       {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
    for (int num_terms = 0; num_terms <= 2; ++num_terms) {
      SCOPED_TRACE(10 * static_cast<int>(profile) + num_terms);
      const RadialIntrinsics truth = Truth(profile, num_terms);
      const RadialIntrinsicsScene scene =
          MakeRadialIntrinsicsScene(truth, 200, MaxAngleDeg(profile), 20);
      const std::vector<RadialIntrinsics> models =
          SolveRadialIntrinsicsLeastSquares(scene.x, scene.points_cam, profile,
                                            num_terms, truth.focal);
      ASSERT_FALSE(models.empty());
      EXPECT_LT(RelativeError(models[0], truth, 1), 1e-8);
      for (const RadialIntrinsics& model : models) {
        EXPECT_EQ(model.focal, truth.focal);
      }
    }
  }
}

// With the true f given, 0.5 px noise on 500 points: tz and k at least as
// close as with f estimated (NoisyData's bounds), f exact.
TEST(SolveRadialIntrinsicsLeastSquares, KnownFocalNoisyData) {
  for (const RadialProfile profile :
       {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
    SCOPED_TRACE(static_cast<int>(profile));
    const RadialIntrinsics truth = Truth(profile, 2);
    RadialIntrinsicsScene scene =
        MakeRadialIntrinsicsScene(truth, 500, MaxAngleDeg(profile), 7);
    testing::AddNoiseAndOutliers(0.5, 0, 8, &scene);
    const std::vector<RadialIntrinsics> models =
        SolveRadialIntrinsicsLeastSquares(scene.x, scene.points_cam, profile, 2,
                                          truth.focal);
    ASSERT_FALSE(models.empty());
    EXPECT_EQ(models[0].focal, truth.focal);
    EXPECT_NEAR(models[0].tz, truth.tz, 0.002);
    EXPECT_NEAR(models[0].k[0], truth.k[0], 0.005);
    EXPECT_NEAR(models[0].k[1], truth.k[1], 0.005);
    std::cout << (profile == RadialProfile::kPolynomial ? "polynomial"
                                                        : "equidistant")
              << " f known: |tz error| " << std::abs(models[0].tz - truth.tz)
              << " m, |k1 error| " << std::abs(models[0].k[0] - truth.k[0])
              << ", |k2 error| " << std::abs(models[0].k[1] - truth.k[1])
              << "\n";
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

}  // namespace
}  // namespace rig_calibrator
