#include "src/estimators/radial_intrinsics_estimator.h"

#include <colmap/optim/loransac.h>
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <limits>
#include <vector>

#include "tests/src/solvers/radial_intrinsics_scene.h"

namespace rig_calibrator {
namespace radial_intrinsics_estimator_test {

using testing::MakeRadialIntrinsics;
using testing::MakeRadialIntrinsicsScene;
using testing::RadialIntrinsicsScene;

TEST(RadialIntrinsicsEstimator, ResidualsAreSquaredReprojectionErrors) {
  const RadialIntrinsics truth = MakeRadialIntrinsics(
      RadialProfile::kEquidistant, 2, 0.4, 300, 0.03, -0.005);
  RadialIntrinsicsScene scene = MakeRadialIntrinsicsScene(truth, 3, 60, 9);
  scene.x[1] += Eigen::Vector2d(3, -4);
  scene.points_cam[2].z() = -0.5;  // behind the camera
  std::vector<double> residuals;
  RadialIntrinsicsEstimator<2> estimator;
  estimator.Residuals(scene.x, scene.points_cam, truth, &residuals);
  ASSERT_EQ(residuals.size(), 3);
  EXPECT_LT(residuals[0], 1e-18);
  EXPECT_NEAR(residuals[1], 25, 1e-9);
  EXPECT_EQ(residuals[2], std::numeric_limits<double>::max());
  std::vector<double> local_residuals;
  RadialIntrinsicsLocalEstimator<2>().Residuals(scene.x, scene.points_cam,
                                                truth, &local_residuals);
  EXPECT_EQ(local_residuals, residuals);
}

// The estimators pass their profile and number of terms on: a minimal
// sample gives the minimal solver's solutions, a larger set the least-squares
// one.
TEST(RadialIntrinsicsEstimator, EstimatesWithItsProfile) {
  const RadialIntrinsics truth =
      MakeRadialIntrinsics(RadialProfile::kEquidistant, 1, 0.4, 300, 0.03, 0);
  const RadialIntrinsicsScene scene =
      MakeRadialIntrinsicsScene(truth, 20, 75, 10);
  RadialIntrinsicsEstimator<1> estimator;
  estimator.profile = RadialProfile::kEquidistant;
  const std::vector<RadialIntrinsics> minimal = estimator.Estimate(
      {scene.x.begin(), scene.x.begin() + 3},
      {scene.points_cam.begin(), scene.points_cam.begin() + 3});
  ASSERT_FALSE(minimal.empty());
  bool found = false;
  for (const RadialIntrinsics& model : minimal) {
    EXPECT_EQ(model.profile, RadialProfile::kEquidistant);
    EXPECT_EQ(model.num_radial_terms, 1);
    found |= testing::RelativeError(model, truth, 1) < 1e-8;
  }
  EXPECT_TRUE(found);
  RadialIntrinsicsLocalEstimator<1> local_estimator;
  local_estimator.profile = RadialProfile::kEquidistant;
  const std::vector<RadialIntrinsics> local =
      local_estimator.Estimate(scene.x, scene.points_cam);
  ASSERT_FALSE(local.empty());
  EXPECT_LT(testing::RelativeError(local[0], truth, 1), 1e-8);
}

// LO-RANSAC with both estimators on 500 points, 0.5 px noise and
// `outlier_ratio` outliers moved 20-200 px, for each profile and number of
// terms, with f free or (kKnownFocal) the true f given. Measured at 30 %
// outliers: every inlier found, no outlier accepted, focal <= 0.05 %,
// tz <= 1 mm, k <= 0.0007; with f known (printed), at 30 and 50 % outliers:
// every inlier found, no outlier accepted, tz <= 0.8 mm, k <= 0.0011, f the
// given value bit for bit.
template <int kNumRadialTerms, bool kKnownFocal>
void ExpectRansacRecovers(const RadialProfile profile,
                          const double outlier_ratio) {
  SCOPED_TRACE(100 * kKnownFocal + 10 * static_cast<int>(profile) +
               kNumRadialTerms);
  const RadialIntrinsics truth =
      profile == RadialProfile::kPolynomial
          ? MakeRadialIntrinsics(profile, kNumRadialTerms, 0.4, 500, -0.3, 0.08)
          : MakeRadialIntrinsics(profile, kNumRadialTerms, 0.4, 300, 0.03,
                                 -0.005);
  RadialIntrinsicsScene scene = MakeRadialIntrinsicsScene(
      truth, 500, profile == RadialProfile::kPolynomial ? 45 : 75, 11);
  const std::vector<char> is_outlier =
      testing::AddNoiseAndOutliers(0.5, outlier_ratio, 12, &scene);
  colmap::RANSACOptions options;
  options.max_error = 4;
  options.confidence = 0.9999;
  options.min_num_trials = 50;
  colmap::LORANSAC<RadialIntrinsicsEstimator<kNumRadialTerms, kKnownFocal>,
                   RadialIntrinsicsLocalEstimator<kNumRadialTerms, kKnownFocal>>
      ransac(options);
  ransac.estimator.profile = profile;
  ransac.local_estimator.profile = profile;
  ransac.estimator.known_focal = truth.focal;
  ransac.local_estimator.known_focal = truth.focal;
  const auto report = ransac.Estimate(scene.x, scene.points_cam);
  ASSERT_TRUE(report.success);
  int num_missed_inliers = 0, num_accepted_outliers = 0;
  for (size_t i = 0; i < is_outlier.size(); ++i) {
    num_missed_inliers += !is_outlier[i] && !report.inlier_mask[i];
    num_accepted_outliers += is_outlier[i] && report.inlier_mask[i];
  }
  EXPECT_EQ(num_missed_inliers, 0);
  EXPECT_EQ(num_accepted_outliers, 0);
  if (kKnownFocal) {
    EXPECT_EQ(report.model.focal, truth.focal);
  } else {
    EXPECT_NEAR(report.model.focal, truth.focal, 0.001 * truth.focal);
  }
  EXPECT_NEAR(report.model.tz, truth.tz, 0.003);
  EXPECT_NEAR(report.model.k[0], truth.k[0], 0.003);
  EXPECT_NEAR(report.model.k[1], truth.k[1], 0.003);
  if (kKnownFocal) {
    std::cout << (profile == RadialProfile::kPolynomial ? "polynomial"
                                                        : "equidistant")
              << " with " << kNumRadialTerms << " terms, f known, "
              << 100 * outlier_ratio << " % outliers: " << report.num_trials
              << " trials, |tz error| " << std::abs(report.model.tz - truth.tz)
              << " m, |k1 error| " << std::abs(report.model.k[0] - truth.k[0])
              << ", |k2 error| " << std::abs(report.model.k[1] - truth.k[1])
              << "\n";
  }
}

TEST(RadialIntrinsicsEstimator, LoRansacOnNoisyDataWithOutliers) {
  for (const RadialProfile profile :
       {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
    ExpectRansacRecovers<0, false>(profile, 0.3);
    ExpectRansacRecovers<1, false>(profile, 0.3);
    ExpectRansacRecovers<2, false>(profile, 0.3);
  }
}

TEST(RadialIntrinsicsEstimator, KnownFocalLoRansacOnNoisyDataWithOutliers) {
  for (const RadialProfile profile :
       {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
    for (const double outlier_ratio : {0.3, 0.5}) {
      ExpectRansacRecovers<0, true>(profile, outlier_ratio);
      ExpectRansacRecovers<1, true>(profile, outlier_ratio);
      ExpectRansacRecovers<2, true>(profile, outlier_ratio);
    }
  }
}

// With a known f the minimal estimator needs one correspondence less and
// both estimators return that f exactly: on exact data the minimal sample
// of n + 1 points and the least squares on all points give the truth.
TEST(RadialIntrinsicsEstimator, KnownFocalEstimatesWithTheGivenFocal) {
  static_assert(RadialIntrinsicsEstimator<1, true>::kMinNumSamples == 2);
  static_assert(RadialIntrinsicsLocalEstimator<1, true>::kMinNumSamples == 3);
  static_assert(RadialIntrinsicsEstimator<1>::kMinNumSamples == 3);
  const RadialIntrinsics truth =
      MakeRadialIntrinsics(RadialProfile::kEquidistant, 1, 0.4, 300, 0.03, 0);
  const RadialIntrinsicsScene scene =
      MakeRadialIntrinsicsScene(truth, 20, 75, 10);
  RadialIntrinsicsEstimator<1, true> estimator;
  estimator.profile = RadialProfile::kEquidistant;
  estimator.known_focal = truth.focal;
  const std::vector<RadialIntrinsics> minimal = estimator.Estimate(
      {scene.x.begin(), scene.x.begin() + 2},
      {scene.points_cam.begin(), scene.points_cam.begin() + 2});
  ASSERT_FALSE(minimal.empty());
  bool found = false;
  for (const RadialIntrinsics& model : minimal) {
    EXPECT_EQ(model.focal, truth.focal);
    found |= testing::RelativeError(model, truth, 1) < 1e-8;
  }
  EXPECT_TRUE(found);
  RadialIntrinsicsLocalEstimator<1, true> local_estimator;
  local_estimator.profile = RadialProfile::kEquidistant;
  local_estimator.known_focal = truth.focal;
  const std::vector<RadialIntrinsics> local =
      local_estimator.Estimate(scene.x, scene.points_cam);
  ASSERT_FALSE(local.empty());
  EXPECT_EQ(local[0].focal, truth.focal);
  EXPECT_LT(testing::RelativeError(local[0], truth, 1), 1e-8);

  // EstimateRadialIntrinsicsRansac passes the known f on, and refuses one
  // that is not finite and positive.
  colmap::RANSACOptions options;
  options.max_error = 4;
  RadialIntrinsics model;
  ASSERT_TRUE(EstimateRadialIntrinsicsRansac(
      options, RadialProfile::kEquidistant, 1, truth.focal, scene.x,
      scene.points_cam, &model));
  EXPECT_EQ(model.focal, truth.focal);
  EXPECT_LT(testing::RelativeError(model, truth, 1), 1e-8);
  for (const double bad_focal :
       {0.0, -truth.focal, std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_FALSE(EstimateRadialIntrinsicsRansac(
        options, RadialProfile::kEquidistant, 1, bad_focal, scene.x,
        scene.points_cam, &model));
  }
}

}  // namespace radial_intrinsics_estimator_test
}  // namespace rig_calibrator
