#include "src/solvers/radial_profile_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "tests/src/solvers/radial_intrinsics_scene.h"

namespace rig_calibrator {
namespace radial_profile_fit_test {

using testing::MakeRadialIntrinsics;
using testing::MakeRadialIntrinsicsScene;
using testing::RadialIntrinsicsScene;
using testing::RelativeError;

RadialIntrinsics Truth(const RadialProfile profile) {
  return profile == RadialProfile::kPolynomial
             ? MakeRadialIntrinsics(profile, 2, 1.3, 500, -0.3, 0.08)
             : MakeRadialIntrinsics(profile, 2, 1.3, 300, 0.03, -0.005);
}

TEST(FitRadialProfile, ExactAtTheTrueTz) {
  for (const RadialProfile profile :
       {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
    const RadialIntrinsics truth = Truth(profile);
    const RadialIntrinsicsScene scene =
        MakeRadialIntrinsicsScene(truth, 100, 45, 5);
    RadialIntrinsics model = truth;
    model.focal = 1;
    model.k[0] = model.k[1] = 0;
    double squared_error = -1;
    ASSERT_TRUE(FitRadialProfile(scene.x, scene.points_cam, std::nullopt,
                                 &model, &squared_error));
    EXPECT_LT(RelativeError(model, truth, 1), 1e-10);
    EXPECT_LT(squared_error, 1e-16);
    // Any other tz fits worse.
    model.tz = truth.tz + 0.1;
    ASSERT_TRUE(FitRadialProfile(scene.x, scene.points_cam, std::nullopt,
                                 &model, &squared_error));
    EXPECT_GT(squared_error, 1);
    // Points behind the camera.
    model.tz = -100;
    EXPECT_FALSE(FitRadialProfile(scene.x, scene.points_cam, std::nullopt,
                                  &model, &squared_error));
  }
}

// Fewer terms than the truth leave a residual; the terms beyond
// num_radial_terms are 0.
TEST(FitRadialProfile, OnlyTheRequestedTerms) {
  const RadialIntrinsics truth = Truth(RadialProfile::kPolynomial);
  const RadialIntrinsicsScene scene =
      MakeRadialIntrinsicsScene(truth, 100, 45, 6);
  RadialIntrinsics model = truth;
  model.num_radial_terms = 1;
  double squared_error = 0;
  ASSERT_TRUE(FitRadialProfile(scene.x, scene.points_cam, std::nullopt, &model,
                               &squared_error));
  EXPECT_EQ(model.k[1], 0);
  EXPECT_GT(squared_error, 1);
  model.num_radial_terms = 3;
  EXPECT_FALSE(FitRadialProfile(scene.x, scene.points_cam, std::nullopt, &model,
                                &squared_error));
}

// From tz 0.3 m off the truth, Gauss-Newton reaches the truth on exact data
// and the least-squares optimum on noisy data (a lower error than at the
// true tz, with the truth within the noise).
TEST(RefineRadialProfileAndTz, ConvergesFromAWrongTz) {
  for (const RadialProfile profile :
       {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
    const RadialIntrinsics truth = Truth(profile);
    RadialIntrinsicsScene scene = MakeRadialIntrinsicsScene(truth, 200, 45, 7);
    RadialIntrinsics model = truth;
    model.tz += 0.3;
    double squared_error = -1;
    ASSERT_TRUE(RefineRadialProfileAndTz(
        scene.x, scene.points_cam, std::nullopt, 10, &model, &squared_error));
    EXPECT_LT(RelativeError(model, truth, 1), 1e-10);
    EXPECT_LT(squared_error, 1e-16);

    testing::AddNoiseAndOutliers(0.5, 0, 8, &scene);
    RadialIntrinsics at_truth = truth;
    double error_at_truth = 0;
    ASSERT_TRUE(FitRadialProfile(scene.x, scene.points_cam, std::nullopt,
                                 &at_truth, &error_at_truth));
    model = truth;
    model.tz += 0.3;
    ASSERT_TRUE(RefineRadialProfileAndTz(
        scene.x, scene.points_cam, std::nullopt, 10, &model, &squared_error));
    EXPECT_LT(squared_error, error_at_truth);
    EXPECT_NEAR(model.tz, truth.tz, 0.05);
    EXPECT_NEAR(model.focal, truth.focal, 0.01 * truth.focal);
  }
}

// Truth(profile) with only its first num_terms distortion terms.
RadialIntrinsics TruthWithTerms(const RadialProfile profile,
                                const int num_terms) {
  RadialIntrinsics truth = Truth(profile);
  truth.num_radial_terms = num_terms;
  for (int j = num_terms; j < 2; ++j) truth.k[j] = 0;
  return truth;
}

// With the true f given: at the true tz the distortion terms are exact for
// 0, 1 and 2 terms (no unknown at all for 0 terms, only the error), and f is
// the given value bit for bit; a known f that is not finite and positive is
// refused.
TEST(FitRadialProfile, KnownFocalExactAtTheTrueTz) {
  for (const RadialProfile profile :
       {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
    for (int num_terms = 0; num_terms <= 2; ++num_terms) {
      SCOPED_TRACE(10 * static_cast<int>(profile) + num_terms);
      const RadialIntrinsics truth = TruthWithTerms(profile, num_terms);
      const RadialIntrinsicsScene scene =
          MakeRadialIntrinsicsScene(truth, 100, 45, 5);
      RadialIntrinsics model = truth;
      model.focal = 1;
      model.k[0] = model.k[1] = 0.5;
      double squared_error = -1;
      ASSERT_TRUE(FitRadialProfile(scene.x, scene.points_cam, truth.focal,
                                   &model, &squared_error));
      EXPECT_EQ(model.focal, truth.focal);
      EXPECT_LT(RelativeError(model, truth, 1), 1e-10);
      EXPECT_LT(squared_error, 1e-16);
      // A 2 % wrong f does not fit.
      ASSERT_TRUE(FitRadialProfile(scene.x, scene.points_cam,
                                   1.02 * truth.focal, &model, &squared_error));
      EXPECT_EQ(model.focal, 1.02 * truth.focal);
      EXPECT_GT(squared_error, 1);
      for (const double bad_focal :
           {0.0, -truth.focal, std::numeric_limits<double>::quiet_NaN()}) {
        EXPECT_FALSE(FitRadialProfile(scene.x, scene.points_cam, bad_focal,
                                      &model, &squared_error));
      }
    }
  }
}

// With the true f given, from tz 0.3 m off the truth Gauss-Newton over tz
// and k reaches the truth on exact data with f unchanged bit for bit; on
// noisy data it reaches the optimum (a lower error than at the true tz).
TEST(RefineRadialProfileAndTz, KnownFocalConvergesFromAWrongTz) {
  for (const RadialProfile profile :
       {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
    for (int num_terms = 0; num_terms <= 2; ++num_terms) {
      SCOPED_TRACE(10 * static_cast<int>(profile) + num_terms);
      const RadialIntrinsics truth = TruthWithTerms(profile, num_terms);
      RadialIntrinsicsScene scene =
          MakeRadialIntrinsicsScene(truth, 200, 45, 7);
      RadialIntrinsics model = truth;
      model.tz += 0.3;
      double squared_error = -1;
      ASSERT_TRUE(RefineRadialProfileAndTz(
          scene.x, scene.points_cam, truth.focal, 10, &model, &squared_error));
      EXPECT_EQ(model.focal, truth.focal);
      EXPECT_LT(RelativeError(model, truth, 1), 1e-10);
      EXPECT_LT(squared_error, 1e-16);

      testing::AddNoiseAndOutliers(0.5, 0, 8, &scene);
      RadialIntrinsics at_truth = truth;
      double error_at_truth = 0;
      ASSERT_TRUE(FitRadialProfile(scene.x, scene.points_cam, truth.focal,
                                   &at_truth, &error_at_truth));
      model = truth;
      model.tz += 0.3;
      ASSERT_TRUE(RefineRadialProfileAndTz(
          scene.x, scene.points_cam, truth.focal, 10, &model, &squared_error));
      EXPECT_EQ(model.focal, truth.focal);
      EXPECT_LT(squared_error, error_at_truth);
      EXPECT_NEAR(model.tz, truth.tz, 0.02);
    }
  }
}

}  // namespace radial_profile_fit_test
}  // namespace rig_calibrator
