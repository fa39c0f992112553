// SharedParameterSpread and AddModelChoiceSpread on hand-made cameras: the
// spread of the focal lengths and principal point, compared axis by axis or
// through the mean focal length, with each alternative's jackknife over its
// fold fits, exact to the last bit; the larger of it and the adjustment's
// sigma reported, held and undetermined parameters left.
#include "src/calibration/model_choice_spread.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "src/calibration/pipeline.h"
#include "src/synthetic/synthetic_rig.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace model_choice_spread_test {

using testing::MakeCamera;

colmap::Camera RadialFisheye() {
  return MakeCamera("RADIAL_FISHEYE", 640, 480, {500, 320, 240, 0.02, -0.01});
}

colmap::Camera OpencvFisheye(double fx, double fy, double cx, double cy) {
  return MakeCamera("OPENCV_FISHEYE", 640, 480,
                    {fx, fy, cx, cy, 0.02, -0.01, 0.003, -0.0005});
}

// One focal length against OPENCV_FISHEYE's fx, fy (mean 502) and
// SIMPLE_RADIAL_FISHEYE's f, without fold fits: the largest difference per
// quantity; the distortion has no counterpart.
TEST(ModelChoiceSpread, OneFocalLengthAgainstTheMeanFocalLength) {
  const std::vector<AlternativeModelFit> others = {
      {OpencvFisheye(501, 503, 321.5, 239), {}},
      {MakeCamera("SIMPLE_RADIAL_FISHEYE", 640, 480, {498.5, 320.25, 240.75, 0.01}),
       {}}};
  const std::vector<double> spread =
      SharedParameterSpread(RadialFisheye(), others);
  const std::vector<double> expected = {2.0, 1.5, 1.0, 0.0, 0.0};
  EXPECT_EQ(spread, expected);
}

// Two focal lengths against one: each axis against the other's f.
TEST(ModelChoiceSpread, TwoFocalLengthsAxisByAxis) {
  const std::vector<double> spread = SharedParameterSpread(
      OpencvFisheye(501, 503, 321.5, 239), {{RadialFisheye(), {}}});
  const std::vector<double> expected = {1.0, 3.0, 1.5, 1.0, 0, 0, 0, 0};
  EXPECT_EQ(spread, expected);
}

// Three fold fits of the alternative: mean focal lengths 501, 502, 503
// (mean 502, jackknife variance 2/3 * 2 = 4/3) and principal points 321.5
// each (none): s = sqrt(d^2 + 4/3) for the focal length, d for cx.
TEST(ModelChoiceSpread, AlternativesOwnJackknifeAdds) {
  const AlternativeModelFit alternative = {
      OpencvFisheye(501, 503, 321.5, 239),
      {OpencvFisheye(500, 502, 321.5, 239), OpencvFisheye(501, 503, 321.5, 239),
       OpencvFisheye(502, 504, 321.5, 239)}};
  const std::vector<double> spread =
      SharedParameterSpread(RadialFisheye(), {alternative});
  EXPECT_DOUBLE_EQ(spread[0], std::sqrt(4.0 + 4.0 / 3.0));
  EXPECT_DOUBLE_EQ(spread[1], 1.5);
  EXPECT_DOUBLE_EQ(spread[2], 1.0);
}

TEST(ModelChoiceSpread, NoOtherCandidateNoSpread) {
  EXPECT_EQ(SharedParameterSpread(RadialFisheye(), {}),
            std::vector<double>(5, 0.0));
}

// sigma' = max(sigma, s) where a parameter is free; a held one (0) and an
// undetermined one (NaN) stay, and so does everything when the spread
// belongs to another model (another size) or is nowhere the larger.
TEST(ModelChoiceSpread, TheLargerReportedHeldAndUndeterminedLeft) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CameraUncertainty uncertainty;
  uncertainty.params_stddev = {1.5, 0.0, nan, 1e-3, 1e-4};
  AddModelChoiceSpread({2.0, 1.5, 1.0, 0.0, 0.0}, &uncertainty);
  EXPECT_EQ(uncertainty.params_stddev[0], 2.0);
  EXPECT_EQ(uncertainty.params_stddev[1], 0.0);
  EXPECT_TRUE(std::isnan(uncertainty.params_stddev[2]));
  EXPECT_EQ(uncertainty.params_stddev[3], 1e-3);
  EXPECT_EQ(uncertainty.params_stddev[4], 1e-4);
  const std::vector<double> added = {2.0, 0.0, 0.0, 0.0, 0.0};
  EXPECT_EQ(uncertainty.model_choice_stddev, added);

  CameraUncertainty other_model;
  other_model.params_stddev = {1.5, 0.5, 0.5, 1e-3, 1e-4};
  const std::vector<double> before = other_model.params_stddev;
  AddModelChoiceSpread({2.0, 1.5, 1.0, 0, 0, 0, 0, 0}, &other_model);
  AddModelChoiceSpread({}, &other_model);
  AddModelChoiceSpread({1.0, 0.25, 0.25, 0, 0}, &other_model);
  EXPECT_EQ(other_model.params_stddev, before);
  EXPECT_TRUE(other_model.model_choice_stddev.empty());
}

// From scratch on the default path (models auto): the synthetic fisheye
// helmet synchronized (40 framesets at 15 Hz, 1080 rows, the default noise,
// wrong matches and missing images). Its cam0 is an OPENCV_FISHEYE lens
// whose k3, k4 the noise hides, and in seeds 1 and 2 the choice gives it
// RADIAL_FISHEYE, whose focal length is 0.38 and 0.43 px off (the
// adjustment's own sigma of it was 0.04 px at 60 framesets, in the 47
// seeds of docs/time_model.md). OPENCV_FISHEYE was as good, and the
// reported sigma is the spread between them (0.37 and 0.39 px): the error
// within 2 sigma. The cameras with the lens's model have no spread, and
// their focal lengths within 3 sigma.
TEST(ModelChoiceSpread, AnotherModelThanTheLensesHasAnHonestFocalSigma) {
  for (const int seed : {1, 2}) {
    SyntheticRigOptions options;
    options.preset = RigPreset::kFisheyeHelmet5;
    options.num_framesets = 40;
    options.points_per_image = 300;
    options.frameset_rate_hz = 15;
    options.image_height = 1080;
    options.seed = seed;
    SyntheticRig rig = GenerateSyntheticRig(options);
    for (RigCamera& camera : rig.dataset.cameras) {
      camera.intrinsics_known = false;
      camera.choose_model = true;
    }
    PipelineOptions pipeline;
    pipeline.print_progress = false;
    pipeline.num_threads = 2;
    RigCalibration calibration;
    PipelineReport report;
    ASSERT_TRUE(CalibrateRig(pipeline, rig.dataset, &calibration, &report))
        << report.error;
    ASSERT_TRUE(report.uncertainty.computed) << report.uncertainty.message;
    for (size_t c = 0; c < rig.truth.cameras.size(); ++c) {
      const colmap::Camera& estimated = calibration.cameras[c];
      const colmap::Camera& truth = rig.truth.cameras[c];
      const CameraUncertainty& sigma = report.uncertainty.cameras[c];
      const size_t focal = estimated.FocalLengthIdxs()[0];
      const double z =
          (estimated.MeanFocalLength() - truth.MeanFocalLength()) /
          sigma.params_stddev[focal];
      std::cout << "seed " << seed << " cam" << c << " "
                << estimated.ModelName() << " focal error / sigma " << z
                << std::endl;
      if (c == 0) {
        EXPECT_EQ(estimated.ModelName(), "RADIAL_FISHEYE") << seed;
        ASSERT_FALSE(sigma.model_choice_stddev.empty()) << seed;
        EXPECT_EQ(sigma.params_stddev[focal], sigma.model_choice_stddev[focal]);
        EXPECT_LT(std::abs(z), 2) << seed;
      } else {
        EXPECT_EQ(estimated.ModelName(), truth.ModelName()) << seed << " " << c;
        EXPECT_TRUE(sigma.model_choice_stddev.empty()) << seed << " " << c;
        EXPECT_LT(std::abs(z), 3) << seed << " " << c;
      }
    }
  }
}

}  // namespace model_choice_spread_test
}  // namespace rig_calibrator
