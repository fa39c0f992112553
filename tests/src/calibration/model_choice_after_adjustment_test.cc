// ChooseModelOnAdjustedRig on one camera's observations of points in the
// rig frame, from scratch: the current camera is another model than the
// truth, with no distortion, and its cam_from_rig is off by about a degree
// and 2 cm. Exact data: the true model chosen and recovered to ~1e-8;
// noisy data with wrong matches: the true model (or, for undistorted
// images, a pinhole) within the noise; a fisheye lens: a fisheye model; a
// current model that folds inside the image: the valid model that fits;
// a simpler model chosen over an as-good flexible one: their focal lengths'
// spread the size of the chosen one's error. And the choice rule's
// standard error clustered by frameset.
#include "src/calibration/model_choice_after_adjustment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "src/evaluation/evaluation.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace model_choice_after_adjustment_test {

using testing::MakeCamera;

const Rigid3d kTrueCamFromRig(
    Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())),
    Eigen::Vector3d(0.12, -0.05, 0.2));

// Per frameset `rows_per_frameset` pixels uniform over the image, their
// rays at depths 2-20 through the true camera, the points in the rig frame;
// `noise_px` Gaussian noise and `outlier_fraction` random pixels.
AdjustedCameraRows MakeRows(const colmap::Camera& truth, int num_framesets,
                            int rows_per_frameset, double noise_px,
                            double outlier_fraction, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> x(0, truth.Width());
  std::uniform_real_distribution<double> y(0, truth.Height());
  std::uniform_real_distribution<double> depth(2, 20);
  std::uniform_real_distribution<double> unit(0, 1);
  std::normal_distribution<double> noise(0, noise_px);
  const Rigid3d rig_from_cam = kTrueCamFromRig.Inverse();
  AdjustedCameraRows rows;
  for (int f = 0; f < num_framesets; ++f) {
    for (int i = 0; i < rows_per_frameset; ++i) {
      const Eigen::Vector2d pixel(x(generator), y(generator));
      Eigen::Vector2d normalized;
      if (!UnprojectPixel(truth, pixel, &normalized)) continue;
      const Eigen::Vector3d point_cam =
          depth(generator) * normalized.homogeneous().normalized();
      Eigen::Vector2d observed = truth.WorldToImage(point_cam.hnormalized());
      observed += Eigen::Vector2d(noise(generator), noise(generator));
      if (unit(generator) < outlier_fraction) {
        observed = Eigen::Vector2d(x(generator), y(generator));
      }
      rows.points2D.push_back(observed);
      rows.points_rig.push_back(rig_from_cam * point_cam);
      rows.framesets.push_back(f);
    }
  }
  return rows;
}

// The current camera: `model` with the truth's size, mean focal length and
// principal point, no distortion; the pose off by ~1 degree and 2 cm.
colmap::Camera StartCamera(const std::string& model,
                           const colmap::Camera& truth) {
  colmap::Camera camera;
  camera.InitializeWithName(model, truth.MeanFocalLength(), truth.Width(),
                            truth.Height());
  camera.SetPrincipalPointX(truth.PrincipalPointX() + 3);
  camera.SetPrincipalPointY(truth.PrincipalPointY() - 2);
  return camera;
}

Rigid3d StartPose() {
  return Rigid3d(
      kTrueCamFromRig.rotation *
          Eigen::Quaterniond(Eigen::AngleAxisd(0.017, Eigen::Vector3d::UnitY())),
      kTrueCamFromRig.translation + Eigen::Vector3d(0.02, 0.0, -0.01));
}

struct Outcome {
  ModelChoice choice;
  colmap::Camera camera;
  Rigid3d cam_from_rig;
  double rotation_error_deg = 0;
  double center_error = 0;
  CameraError projection;
};

Outcome Choose(const colmap::Camera& truth, const colmap::Camera& start,
               const AdjustedCameraRows& rows) {
  Outcome outcome;
  outcome.camera = start;
  outcome.cam_from_rig = StartPose();
  const ModelChoiceAfterAdjustmentOptions options;
  EXPECT_TRUE(ChooseModelOnAdjustedRig(options, rows, &outcome.camera,
                                       &outcome.cam_from_rig, &outcome.choice))
      << outcome.choice.reason;
  std::cout << FormatModelChoice(outcome.choice, "  ");
  outcome.rotation_error_deg = RotationDifferenceDeg(
      outcome.cam_from_rig.rotation, kTrueCamFromRig.rotation);
  outcome.center_error =
      (outcome.cam_from_rig.Center() - kTrueCamFromRig.Center()).norm();
  CompareProjections(truth, outcome.camera, 20, 15, &outcome.projection);
  return outcome;
}

// A function, not a global: COLMAP's model names are registered at static
// initialization too.
colmap::Camera EurocLike() {
  return MakeCamera("OPENCV", 752, 480,
                    {458.7, 457.3, 367.2, 248.4, -0.283, 0.074, 0.0019, -0.0012});
}

// From exact data: the truth's model chosen, its parameters to 1e-6
// (relative) and the rotation to 1e-7 deg.
void ExpectTheTrueModelAndPose(const colmap::Camera& truth,
                               const Outcome& outcome) {
  EXPECT_EQ(outcome.choice.chosen, truth.ModelName());
  ASSERT_EQ(outcome.camera.ModelName(), truth.ModelName());
  for (size_t k = 0; k < truth.Params().size(); ++k) {
    EXPECT_NEAR(outcome.camera.Params()[k], truth.Params()[k],
                1e-6 * std::max(1.0, std::abs(truth.Params()[k])))
        << k;
  }
  EXPECT_LT(outcome.rotation_error_deg, 1e-7);
}

TEST(ModelChoiceAfterAdjustment, ExactDataRecoverTheTrueModelAndPose) {
  const colmap::Camera euroc_like = EurocLike();
  const AdjustedCameraRows rows = MakeRows(euroc_like, 12, 150, 0, 0, 1);
  const Outcome outcome =
      Choose(euroc_like, StartCamera("RADIAL", euroc_like), rows);
  ExpectTheTrueModelAndPose(euroc_like, outcome);
  EXPECT_LT(outcome.center_error, 1e-8);
}

TEST(ModelChoiceAfterAdjustment, NoisyDataWithWrongMatchesKeepTangentialTerms) {
  const colmap::Camera euroc_like = EurocLike();
  const AdjustedCameraRows rows = MakeRows(euroc_like, 20, 150, 0.5, 0.2, 2);
  const Outcome outcome =
      Choose(euroc_like, StartCamera("OPENCV_FISHEYE", euroc_like), rows);
  EXPECT_EQ(outcome.choice.chosen, "OPENCV");
  EXPECT_FALSE(outcome.choice.uncertain);
  EXPECT_LT(outcome.rotation_error_deg, 0.05);
  EXPECT_LT(outcome.center_error, 0.01);
  EXPECT_LT(outcome.projection.mean_projection_diff_px, 0.3);
}

// A rectified camera (no distortion): the flexible model the upgrade may
// have chosen gives way to a pinhole, and the pose does not trade with the
// principal point.
TEST(ModelChoiceAfterAdjustment, UndistortedImagesGetAPinhole) {
  const colmap::Camera truth =
      MakeCamera("PINHOLE", 1241, 376, {718.9, 718.9, 607.2, 185.2});
  const AdjustedCameraRows exact = MakeRows(truth, 12, 150, 0, 0, 3);
  const Outcome from_exact = Choose(truth, StartCamera("OPENCV", truth), exact);
  EXPECT_EQ(from_exact.choice.chosen, "SIMPLE_PINHOLE");
  EXPECT_LT(from_exact.rotation_error_deg, 1e-7);
  EXPECT_LT(from_exact.projection.max_projection_diff_px, 1e-6);

  const AdjustedCameraRows noisy = MakeRows(truth, 20, 150, 0.5, 0.2, 4);
  const Outcome from_noisy = Choose(truth, StartCamera("OPENCV", truth), noisy);
  EXPECT_TRUE(from_noisy.choice.chosen == "SIMPLE_PINHOLE" ||
              from_noisy.choice.chosen == "PINHOLE")
      << from_noisy.choice.chosen;
  EXPECT_LT(from_noisy.rotation_error_deg, 0.05);
  EXPECT_LT(from_noisy.projection.mean_projection_diff_px, 0.3);
}

// 144 degrees over the diagonal.
TEST(ModelChoiceAfterAdjustment, FisheyeLensGetsAFisheyeModel) {
  const colmap::Camera truth = MakeCamera(
      "OPENCV_FISHEYE", 800, 800, {450, 450, 400, 400, 0.05, -0.01, 0.002, 0});
  const AdjustedCameraRows rows = MakeRows(truth, 20, 150, 0.5, 0.1, 5);
  const Outcome outcome =
      Choose(truth, StartCamera("RADIAL_FISHEYE", truth), rows);
  EXPECT_NE(outcome.choice.chosen.find("FISHEYE"), std::string::npos)
      << outcome.choice.chosen;
  EXPECT_LT(outcome.rotation_error_deg, 0.05);
  EXPECT_LT(outcome.projection.mean_projection_diff_px, 0.3);
}

// No choice (false) from `start_model`, the camera and pose unchanged,
// and the reason containing `reason`.
void ExpectNoChoice(const colmap::Camera& truth, const std::string& start_model,
                    const AdjustedCameraRows& rows, const std::string& reason) {
  colmap::Camera camera = StartCamera(start_model, truth);
  const colmap::Camera start = camera;
  Rigid3d cam_from_rig = StartPose();
  ModelChoice choice;
  EXPECT_FALSE(ChooseModelOnAdjustedRig(ModelChoiceAfterAdjustmentOptions(),
                                        rows, &camera, &cam_from_rig, &choice));
  EXPECT_EQ(camera.ModelName(), start.ModelName());
  EXPECT_EQ(camera.Params(), start.Params());
  EXPECT_EQ(cam_from_rig.translation, StartPose().translation);
  EXPECT_EQ(choice.chosen, "");
  EXPECT_NE(choice.reason.find(reason), std::string::npos) << choice.reason;
}

// A lens beyond 90 degrees at the corners, which no COLMAP model can
// represent: the current model folds inside the image, and the valid
// candidates (a pinhole wins among them) do not fit the data as well as it
// does, so nothing changes and its error stands.
TEST(ModelChoiceAfterAdjustment, NoChangeWhenTheCurrentModelIsNotValid) {
  const colmap::Camera truth = MakeCamera(
      "OPENCV_FISHEYE", 800, 800, {280, 280, 400, 400, 0.05, -0.01, 0.002, 0});
  ExpectNoChoice(truth, "RADIAL_FISHEYE", MakeRows(truth, 20, 150, 0.5, 0.1, 7),
                 "RADIAL_FISHEYE, was not valid over the whole image when "
                 "fitted on the adjusted rig, and no valid candidate fits the "
                 "data as well");
}

// The synthetic ring's lens (an OPENCV lens at 640 x 480 with strong
// barrel distortion, the 500 x 10 benchmark's cam1), for which the upgrade
// can choose RADIAL_FISHEYE: fitted on the adjusted rig, it folds inside
// the image, and the best valid candidate replaces it when it fits as well.
colmap::Camera RingLike() {
  return MakeCamera("OPENCV", 640, 480,
                    {445, 444, 302, 245, -0.32, 0.07, -0.0005, 0.0002});
}

TEST(ModelChoiceAfterAdjustment, AnInvalidCurrentModelGivesWayToAValidOne) {
  const colmap::Camera ring_like = RingLike();
  const Outcome exact =
      Choose(ring_like, StartCamera("RADIAL_FISHEYE", ring_like),
             MakeRows(ring_like, 12, 150, 0, 0, 8));
  EXPECT_NE(exact.choice.reason.find("replaces RADIAL_FISHEYE, which was not "
                                     "valid"),
            std::string::npos)
      << exact.choice.reason;
  ExpectTheTrueModelAndPose(ring_like, exact);

  const Outcome noisy =
      Choose(ring_like, StartCamera("RADIAL_FISHEYE", ring_like),
             MakeRows(ring_like, 20, 150, 0.5, 0.2, 9));
  EXPECT_EQ(noisy.choice.chosen, "OPENCV");
  EXPECT_LT(noisy.rotation_error_deg, 0.05);
  EXPECT_LT(noisy.projection.mean_projection_diff_px, 0.3);
}

TEST(ModelChoiceAfterAdjustment, OneFramesetIsNoChoice) {
  const colmap::Camera euroc_like = EurocLike();
  ExpectNoChoice(euroc_like, "RADIAL", MakeRows(euroc_like, 1, 300, 0, 0, 6),
                 "one frameset");
}

// Four framesets: a lens with one focal length and no tangential distortion
// (RADIAL) seen by a camera whose current model is OPENCV. RADIAL is as good
// held out, but four clusters do not make that sure, and OPENCV is kept;
// with twenty framesets RADIAL wins, OPENCV as good, their focal lengths and
// principal points apart by the noise (the spread).
TEST(ModelChoiceAfterAdjustment, FewFramesetsKeepTheCurrentModelUnlessItIsWorse) {
  const colmap::Camera truth = MakeCamera(
      "OPENCV", 752, 480, {458.0, 458.0, 367.2, 248.4, -0.283, 0.074, 0, 0});
  const Outcome few =
      Choose(truth, StartCamera("OPENCV", truth), MakeRows(truth, 4, 300, 0.5, 0, 8));
  EXPECT_EQ(few.choice.chosen, "OPENCV");
  EXPECT_NE(few.choice.reason.find("OPENCV kept: with 4 framesets"),
            std::string::npos)
      << few.choice.reason;
  const Outcome many =
      Choose(truth, StartCamera("OPENCV", truth), MakeRows(truth, 20, 150, 0.5, 0, 8));
  EXPECT_EQ(many.choice.chosen, "RADIAL") << many.choice.reason;
  // OPENCV was as good: its fit of the same lens differs by the noise.
  EXPECT_EQ(many.choice.spread_models, std::vector<std::string>{"OPENCV"});
  ASSERT_EQ(many.choice.parameter_spread.size(), 5u);
  // With OPENCV's own jackknife: f 0.07 px, the principal point 0.13 and
  // 0.12 px (OPENCV's tangential terms trade with it), at the noise level.
  EXPECT_LT(many.choice.parameter_spread[0], 0.15);
  EXPECT_LT(many.choice.parameter_spread[1], 0.25);
  EXPECT_LT(many.choice.parameter_spread[2], 0.25);
}

// The synthetic fisheye helmet's cam0 (an OPENCV_FISHEYE lens, 150 degrees
// over the diagonal, k3 and k4 small), whose k3, k4 the noise hides: a
// simpler model is as good held out, and which one is chosen moves the
// focal length. Every candidate as good as the best is named in
// spread_models, and parameter_spread (model_choice_spread.h) holds how
// far the chosen focal length and principal point may be off if one of
// them is the lens's (its difference and its own jackknife): here the size
// of the chosen focal length's error. From exact data the lens's model
// alone is as good as the best, and there is no spread.
TEST(ModelChoiceAfterAdjustment, CandidatesAsGoodAsTheBestGiveTheSpread) {
  const colmap::Camera truth =
      MakeCamera("OPENCV_FISHEYE", 640, 480,
                 {300.9, 300.9, 326, 235, 0.020, -0.010, 0.003, -0.0005});
  const Outcome exact = Choose(truth, StartCamera("RADIAL_FISHEYE", truth),
                               MakeRows(truth, 20, 150, 0, 0, 10));
  EXPECT_EQ(exact.choice.chosen, "OPENCV_FISHEYE");
  EXPECT_TRUE(exact.choice.parameter_spread.empty());
  EXPECT_TRUE(exact.choice.spread_models.empty());

  const Outcome noisy = Choose(truth, StartCamera("RADIAL_FISHEYE", truth),
                               MakeRows(truth, 20, 150, 0.5, 0.1, 11));
  EXPECT_EQ(noisy.choice.chosen, "RADIAL_FISHEYE");
  EXPECT_EQ(noisy.choice.spread_models,
            std::vector<std::string>{"OPENCV_FISHEYE"});
  ASSERT_EQ(noisy.choice.parameter_spread.size(), 5u);
  // f, cx, cy, k1, k2: the focal length's error (0.23 px) is the size of
  // its spread (0.22 px), which the principal point's (0.03 and 0.07 px,
  // OPENCV_FISHEYE's noise) is not; the distortion has none.
  const double focal_error =
      std::abs(noisy.camera.MeanFocalLength() - truth.MeanFocalLength());
  const std::vector<double>& spread = noisy.choice.parameter_spread;
  EXPECT_GT(focal_error, 0.1);
  EXPECT_LT(focal_error, 2 * spread[0]);
  EXPECT_GT(focal_error, 0.5 * spread[0]);
  EXPECT_LT(spread[1], 0.15);
  EXPECT_LT(spread[2], 0.15);
  EXPECT_EQ(spread[3], 0.0);
  EXPECT_EQ(spread[4], 0.0);
}

// Candidate 1 (more parameters) beats candidate 0 by 0.02 px^2 per row on
// average, but per frameset the difference is +-0.1: as independent rows
// (1000 of them) that is 6 standard errors, clustered by the 10 framesets
// 0.6, and the fewer parameters win.
TEST(ModelChoiceAfterAdjustment, ChoiceRuleClustersTheStandardError) {
  std::vector<std::vector<double>> squared_errors(2);
  std::vector<int> framesets, rows;
  for (int i = 0; i < 1000; ++i) {
    const int frameset = i / 100;
    squared_errors[0].push_back(1.02 + (frameset % 2 ? 0.1 : -0.1));
    squared_errors[1].push_back(1.0);
    framesets.push_back(frameset);
    rows.push_back(i);
  }
  ModelChoice choice;
  choice.candidates.resize(2);
  choice.candidates[0].model = "RADIAL";
  choice.candidates[0].num_params = 5;
  choice.candidates[1].model = "OPENCV";
  choice.candidates[1].num_params = 8;
  ModelChoice by_rows = choice;
  EXPECT_EQ(ChooseByHeldOutError(2.0, squared_errors, rows, "rows", &by_rows),
            1);
  EXPECT_EQ(by_rows.chosen, "OPENCV");
  ModelChoice by_framesets = choice;
  EXPECT_EQ(ChooseByHeldOutError(2.0, squared_errors, framesets, "framesets",
                                 &by_framesets),
            0);
  EXPECT_EQ(by_framesets.chosen, "RADIAL");
}

}  // namespace model_choice_after_adjustment_test
}  // namespace rig_calibrator
