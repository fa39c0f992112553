#include "src/calibration/radial_bundle_adjuster.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "src/calibration/principal_axes.h"
#include "src/calibration/rig_initializer.h"
#include "tests/src/calibration/radial_rig_scene.h"

namespace rig_calibrator {
namespace testing {
namespace radial_bundle_adjuster_test {

// The truth's rig with rotations turned by about `angle_deg` and translations
// moved by about `shift` (tx, ty of the cameras; all of the rig poses): the
// start of the adjustment. Cameras and images as the scene's input.
RigCalibration PerturbedTruth(const RadialRigScene& scene, double angle_deg,
                              double shift, unsigned int seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal;
  auto turn = [&](const Eigen::Quaterniond& rotation) {
    const Eigen::Vector3d axis(normal(random), normal(random), normal(random));
    return RotationAbout(axis, angle_deg) * rotation;
  };
  RigCalibration calibration = scene.input;
  calibration.cam_from_rig = scene.truth.cam_from_rig;
  calibration.camera_calibrated = scene.truth.camera_calibrated;
  calibration.rig_from_world = scene.truth.rig_from_world;
  for (size_t i = 1; i < calibration.cam_from_rig.size(); ++i) {
    Rigid3d& cam_from_rig = calibration.cam_from_rig[i];
    cam_from_rig.rotation = turn(cam_from_rig.rotation);
    cam_from_rig.translation +=
        shift * Eigen::Vector3d(normal(random), normal(random), 0);
    cam_from_rig.translation.z() = 0;
  }
  for (std::optional<Rigid3d>& rig_from_world : calibration.rig_from_world) {
    rig_from_world->rotation = turn(rig_from_world->rotation);
    rig_from_world->translation +=
        shift * Eigen::Vector3d(normal(random), normal(random), normal(random));
  }
  return calibration;
}

double PrincipalPointError(const colmap::Camera& estimate,
                           const colmap::Camera& truth) {
  return std::hypot(estimate.PrincipalPointX() - truth.PrincipalPointX(),
                    estimate.PrincipalPointY() - truth.PrincipalPointY());
}

// Principal points 15 px off. A principal point shift is nearly the same as
// a small pan/tilt of the camera: only the perspective and the distortion
// across the field of view tell them apart, so the scene has a wide-angle
// lens's barrel distortion (k1 = -0.25) and many points per image.
RadialRigSceneOptions OffCenterOptions(double noise_px) {
  RadialRigSceneOptions options;
  options.points_per_image = 300;
  options.k1 = -0.25;
  options.noise_px = noise_px;
  options.principal_point_error_px = 15;
  options.seed = 5;
  return options;
}

TEST(AdjustRadialRig, ExactDataRecoversTruth) {
  const RadialRigScene scene = MakeRadialRigScene(OffCenterOptions(0));
  RigCalibration calibration = PerturbedTruth(scene, 0.5, 0.02, 1);
  RadialBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRadialRig(RadialBundleAdjustmentOptions(), scene.dataset,
                              &calibration, &summary))
      << summary.message;
  EXPECT_GT(summary.initial_rms_px, 1);
  EXPECT_LT(summary.final_rms_px, 1e-6);

  const RigCalibration truth = RadialTruth(scene);
  EXPECT_EQ(calibration.cam_from_rig[0].ToMatrix(), Rigid3d().ToMatrix());
  for (int i = 0; i < 5; ++i) {
    EXPECT_LT(PrincipalPointError(calibration.cameras[i], truth.cameras[i]),
              1e-6)
        << i;
  }
  ExpectRigNear(calibration, truth, 1e-8);
}

TEST(AdjustRadialRig, NoisyDataRecoversPrincipalPointsAndRotations) {
  const RadialRigScene scene = MakeRadialRigScene(OffCenterOptions(0.5));
  RigCalibration calibration = PerturbedTruth(scene, 0.5, 0.02, 2);
  double initial_pp_error = 0;
  for (int i = 0; i < 5; ++i) {
    initial_pp_error = std::max(
        initial_pp_error,
        PrincipalPointError(calibration.cameras[i], scene.truth.cameras[i]));
  }
  EXPECT_NEAR(initial_pp_error, 15, 1e-9);

  RadialBundleAdjustmentOptions options;
  options.num_threads = 2;
  RadialBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRadialRig(options, scene.dataset, &calibration, &summary))
      << summary.message;
  EXPECT_LT(summary.final_rms_px, 0.6);
  EXPECT_EQ(summary.num_framesets_skipped, 0);

  const RigCalibration truth = RadialTruth(scene);
  double max_pp_error = 0, max_rotation_deg = 0, max_rig_rotation_deg = 0;
  for (int i = 0; i < 5; ++i) {
    max_pp_error =
        std::max(max_pp_error,
                 PrincipalPointError(calibration.cameras[i], truth.cameras[i]));
    max_rotation_deg =
        std::max(max_rotation_deg,
                 RotationDifferenceDeg(calibration.cam_from_rig[i].rotation,
                                       truth.cam_from_rig[i].rotation));
  }
  for (size_t j = 0; j < truth.rig_from_world.size(); ++j) {
    max_rig_rotation_deg =
        std::max(max_rig_rotation_deg,
                 RotationDifferenceDeg(calibration.rig_from_world[j]->rotation,
                                       truth.rig_from_world[j]->rotation));
  }
  EXPECT_LT(max_pp_error, 1.0);
  EXPECT_LT(max_rotation_deg, 0.05);
  EXPECT_LT(max_rig_rotation_deg, 0.05);
}

// The radial stages chained on wrong, missing and noisy per-image poses,
// principal points 15 px off and partial framesets. The initializer leaves
// the mis-localized images out of the rig's estimate, but their frameset
// may still have a rig pose: the adjustment must drop them.
TEST(AdjustRadialRig, AfterInitializationWithOutliers) {
  RadialRigSceneOptions scene_options = OffCenterOptions(0.5);
  scene_options.min_cameras_per_frameset = 3;
  scene_options.max_cameras_per_frameset = 5;
  scene_options.garbage_ratio = 0.1;
  scene_options.missing_ratio = 0.1;
  scene_options.pose_noise_deg = 0.1;
  scene_options.pose_noise_translation = 0.005;
  const RadialRigScene scene = MakeRadialRigScene(scene_options);
  RigCalibration calibration = scene.input;
  RigInitializerSummary init_summary;
  ASSERT_TRUE(InitializeRig(RigInitializerOptions(), scene.dataset,
                            &calibration, &init_summary))
      << init_summary.message;
  ASSERT_EQ(init_summary.num_cameras_assigned, 5);

  // Every correspondence in the problem (the pipeline's default takes at
  // most 100 per image), so that every wrong one must be dropped and the
  // accuracy is the adjustment's on all the data.
  RadialBundleAdjustmentOptions options;
  options.max_correspondences_per_image = 0;
  RadialBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRadialRig(options, scene.dataset, &calibration, &summary))
      << summary.message;
  // The mis-localized images' correspondences (all marked inliers) are
  // dropped after the first solve.
  int num_wrong_correspondences = 0;
  for (size_t k = 0; k < scene.garbage.size(); ++k) {
    if (scene.garbage[k] &&
        calibration.rig_from_world[scene.dataset.images[k].frameset_index]) {
      num_wrong_correspondences += scene.input.images[k].inlier_mask.size();
    }
  }
  EXPECT_GE(summary.num_outliers, num_wrong_correspondences);
  EXPECT_LT(summary.final_rms_px, 0.6);
  const RigCalibration truth = RadialTruth(scene);
  for (int i = 0; i < 5; ++i) {
    EXPECT_LT(PrincipalPointError(calibration.cameras[i], truth.cameras[i]),
              1.0)
        << i;
    EXPECT_LT(RotationDifferenceDeg(calibration.cam_from_rig[i].rotation,
                                    truth.cam_from_rig[i].rotation),
              0.05)
        << i;
  }
}

TEST(AdjustRadialRig, FixedPrincipalPointsStayPut) {
  const RadialRigScene scene = MakeRadialRigScene(OffCenterOptions(0));
  RigCalibration calibration = PerturbedTruth(scene, 0.5, 0.02, 3);
  RadialBundleAdjustmentOptions options;
  options.refine_principal_points = false;
  RadialBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRadialRig(options, scene.dataset, &calibration, &summary))
      << summary.message;
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(calibration.cameras[i].PrincipalPointX(),
              scene.input.cameras[i].PrincipalPointX());
    EXPECT_EQ(calibration.cameras[i].PrincipalPointY(),
              scene.input.cameras[i].PrincipalPointY());
  }
  // The wrong principal points leave residuals the poses cannot remove.
  EXPECT_GT(summary.final_rms_px, 0.1);
}

TEST(AdjustRadialRig, RigPoseSeenByOneCameraIsSkipped) {
  const RadialRigScene scene = MakeRadialRigScene(OffCenterOptions(0));
  RigCalibration calibration = PerturbedTruth(scene, 0.2, 0.01, 4);
  // Frameset 0 keeps inliers in one image only.
  bool kept_one = false;
  for (size_t k = 0; k < scene.dataset.images.size(); ++k) {
    if (scene.dataset.images[k].frameset_index != 0) continue;
    if (kept_one) calibration.images[k].inlier_mask.clear();
    kept_one = true;
  }
  const Rigid3d before = *calibration.rig_from_world[0];
  RadialBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRadialRig(RadialBundleAdjustmentOptions(), scene.dataset,
                              &calibration, &summary))
      << summary.message;
  EXPECT_EQ(summary.num_framesets_skipped, 1);
  // Only the origin's slide (NormalizeRadialRigOrigin) moves it.
  EXPECT_EQ(calibration.rig_from_world[0]->rotation.coeffs(),
            before.rotation.coeffs());
}

// A frameset seen by two cameras whose axes are (nearly) parallel or
// anti-parallel does not determine its rig pose: a front/back pair has no
// frameset to adjust, while a pair at right angles has all of them.
TEST(AdjustRadialRig, FramesetsOfAntiParallelPairAreNotAdjusted) {
  for (const double yaw_deg : {178.0, 180.0, 2.0, 90.0}) {
    SCOPED_TRACE("pair yaw " + std::to_string(yaw_deg) + " degrees");
    const RadialRigScene scene = MakePairScene(yaw_deg);
    RigCalibration calibration = PerturbedTruth(scene, 0.2, 0.01, 6);
    RadialBundleAdjustmentSummary summary;
    const bool adjusted = AdjustRadialRig(
        RadialBundleAdjustmentOptions(), scene.dataset, &calibration, &summary);
    if (yaw_deg == 90.0) {
      ASSERT_TRUE(adjusted) << summary.message;
      EXPECT_EQ(summary.num_framesets_skipped, 0);
      EXPECT_LT(summary.final_rms_px, 1e-6);
    } else {
      EXPECT_FALSE(adjusted);
      EXPECT_NE(summary.message.find("framesets with a determined rig pose"),
                std::string::npos)
          << summary.message;
    }
  }
}

TEST(AdjustRadialRig, InconsistentInputFails) {
  const RadialRigScene scene = MakeRadialRigScene(OffCenterOptions(0));
  RigCalibration calibration = PerturbedTruth(scene, 0, 0, 5);
  RadialBundleAdjustmentSummary summary;

  RigCalibration missing_pose = calibration;
  missing_pose.cam_from_rig.pop_back();
  EXPECT_FALSE(AdjustRadialRig(RadialBundleAdjustmentOptions(), scene.dataset,
                               &missing_pose, &summary));
  EXPECT_NE(summary.message.find("do not match"), std::string::npos);

  RigCalibration uncalibrated_reference = calibration;
  uncalibrated_reference.camera_calibrated[0] = false;
  EXPECT_FALSE(AdjustRadialRig(RadialBundleAdjustmentOptions(), scene.dataset,
                               &uncalibrated_reference, &summary));
  EXPECT_NE(summary.message.find("reference camera"), std::string::npos);

  RigCalibration no_inliers = calibration;
  for (ImageResult& image : no_inliers.images) image.inlier_mask.clear();
  EXPECT_FALSE(AdjustRadialRig(RadialBundleAdjustmentOptions(), scene.dataset,
                               &no_inliers, &summary));
  EXPECT_NE(summary.message.find("no inlier correspondences"),
            std::string::npos);
  // Unchanged on failure.
  EXPECT_EQ(no_inliers.cameras[1].PrincipalPointX(),
            calibration.cameras[1].PrincipalPointX());
}

}  // namespace radial_bundle_adjuster_test
}  // namespace testing
}  // namespace rig_calibrator
