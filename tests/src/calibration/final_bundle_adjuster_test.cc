#include "src/calibration/final_bundle_adjuster.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include "tests/src/calibration/final_ba_scene.h"

namespace rig_calibrator {
namespace final_bundle_adjuster_test {

using namespace final_ba_testing;  // NOLINT: the shared test fixture

TEST(FinalBundleAdjusterTest, RecoversExactRigFromPerturbedStart) {
  const SyntheticBaScene rig = MakeSyntheticRig(SceneOptions());
  RigCalibration calibration = PerturbedStart(rig, 2);
  const CalibrationErrors start = Compare(calibration, rig.truth);
  ASSERT_GT(start.rotation_deg, 0.5);
  ASSERT_GT(start.focal_relative, 0.01);

  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset,
                        &calibration, &summary));
  ExpectExactSolution(rig, "exact", calibration, summary);
  EXPECT_GT(summary.initial_rms_px, 5);
  EXPECT_FALSE(summary.solver_report.empty());
  int num_observations = 0;
  for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
    const ImageResult& result = calibration.images[i];
    EXPECT_TRUE(result.used);
    EXPECT_EQ(result.num_inliers,
              static_cast<int>(rig.dataset.images[i].correspondences.size()));
    EXPECT_LT(result.rms_px, 1e-8);
    num_observations += result.num_inliers;
  }
  EXPECT_EQ(summary.num_residuals, num_observations);
  EXPECT_TRUE(calibration.refined_points3D.empty());
  // The reference camera defines the rig frame.
  EXPECT_EQ(calibration.cam_from_rig[0].translation, Eigen::Vector3d::Zero());
  EXPECT_EQ(calibration.cam_from_rig[0].rotation.w(), 1.0);
}

TEST(FinalBundleAdjusterTest, NoisyDataWithOutliersIsAccurateAndPrunesThem) {
  // 300 correspondences per image, as in real data: a principal point error
  // of d px is nearly a rotation of d / f (0.44 px ~ 0.05 deg), so the
  // rotation bound needs the principal point well below 1 px.
  SceneOptions scene;
  scene.num_points_per_image = 300;
  scene.noise_px = 0.5;
  scene.outlier_ratio = 0.1;
  const SyntheticBaScene rig = MakeSyntheticRig(scene);
  RigCalibration calibration = PerturbedStart(rig, 3);

  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset,
                        &calibration, &summary));
  const CalibrationErrors errors = Compare(calibration, rig.truth);
  PrintErrors("noisy", errors, summary);
  EXPECT_LT(errors.rotation_deg, 0.05);
  EXPECT_LT(errors.center, 0.002);
  EXPECT_LT(errors.focal_relative, 0.002);
  EXPECT_LT(errors.principal_point_px, 1);
  EXPECT_LT(errors.k1, 0.005);
  // 0.5 px per coordinate: the RMS of |e| is 0.5 sqrt(2) = 0.71 px.
  EXPECT_NEAR(summary.final_rms_px, 0.5 * std::sqrt(2.0), 0.05);

  int num_gross = 0, num_gross_kept = 0, num_good = 0, num_good_pruned = 0;
  for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
    for (size_t k = 0; k < rig.is_gross_outlier[i].size(); ++k) {
      const bool kept = calibration.images[i].inlier_mask[k];
      if (rig.is_gross_outlier[i][k]) {
        ++num_gross;
        num_gross_kept += kept;
      } else {
        ++num_good;
        num_good_pruned += !kept;
      }
    }
  }
  std::printf(
      "gross outliers kept %d of %d, good observations pruned %d of "
      "%d\n",
      num_gross_kept, num_gross, num_good_pruned, num_good);
  ASSERT_GT(num_gross, 500);
  EXPECT_EQ(num_gross_kept, 0);
  // max(2 px, 4 sigma) prunes |e| > 2 px of 0.5 px noise: exp(-8), ~0.03 %.
  EXPECT_LT(num_good_pruned, 0.002 * num_good);
  EXPECT_EQ(summary.num_outliers, num_gross + num_good_pruned);
}

TEST(FinalBundleAdjusterTest, FixedFocalLengthStaysUnchanged) {
  const SyntheticBaScene rig = MakeSyntheticRig(SceneOptions());
  const RigCalibration start = PerturbedStart(rig, 4);
  RigCalibration calibration = start;
  FinalBundleAdjustmentOptions options;
  options.refine_focal_length = false;
  ASSERT_TRUE(AdjustRig(options, rig.dataset, &calibration, nullptr));
  for (size_t i = 0; i < start.cameras.size(); ++i) {
    const std::vector<double>& p = calibration.cameras[i].Params();
    const std::vector<double>& q = start.cameras[i].Params();
    EXPECT_EQ(p[0], q[0]);
    EXPECT_EQ(p[1], q[1]);
    EXPECT_NE(p[2], q[2]);  // the principal point is still refined
    EXPECT_NE(p[4], q[4]);  // and the distortion
  }
}

TEST(FinalBundleAdjusterTest, KnownIntrinsicsStayUnchangedAndPosesConverge) {
  const SyntheticBaScene rig = MakeSyntheticRig(SceneOptions());
  RigCalibration calibration = PerturbedStart(rig, 5);
  calibration.cameras = rig.truth.cameras;
  FinalBundleAdjustmentOptions options;
  options.refine_focal_length = false;
  options.refine_principal_point = false;
  options.refine_extra_params = false;
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(options, rig.dataset, &calibration, &summary));
  for (size_t i = 0; i < rig.truth.cameras.size(); ++i) {
    EXPECT_EQ(calibration.cameras[i].Params(), rig.truth.cameras[i].Params());
  }
  const CalibrationErrors errors = Compare(calibration, rig.truth);
  PrintErrors("known intrinsics", errors, summary);
  EXPECT_LT(errors.rotation_deg, 1e-8);
  EXPECT_LT(errors.center, 1e-8);
}

TEST(FinalBundleAdjusterTest, NothingToRefineStillPrunesOutliers) {
  SceneOptions scene;
  scene.outlier_ratio = 0.1;
  const SyntheticBaScene rig = MakeSyntheticRig(scene);
  RigCalibration calibration = rig.truth;
  FinalBundleAdjustmentOptions options;
  options.refine_focal_length = false;
  options.refine_principal_point = false;
  options.refine_extra_params = false;
  options.refine_extrinsics = false;
  options.refine_rig_poses = false;
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(options, rig.dataset, &calibration, &summary));
  EXPECT_LT(summary.final_rms_px, 1e-8);
  int num_gross = 0;
  for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
    for (size_t k = 0; k < rig.is_gross_outlier[i].size(); ++k) {
      num_gross += rig.is_gross_outlier[i][k];
      EXPECT_EQ(calibration.images[i].inlier_mask[k],
                !rig.is_gross_outlier[i][k]);
    }
  }
  EXPECT_EQ(summary.num_outliers, num_gross);
  EXPECT_EQ(calibration.cameras[1].Params(), rig.truth.cameras[1].Params());
  EXPECT_EQ(calibration.cam_from_rig[1].translation,
            rig.truth.cam_from_rig[1].translation);
}

TEST(FinalBundleAdjusterTest, FisheyeRigConverges) {
  SceneOptions scene;
  scene.model_id = colmap::OpenCVFisheyeCameraModel::kModelId;
  const SyntheticBaScene rig = MakeSyntheticRig(scene);
  RigCalibration calibration = PerturbedStart(rig, 7);
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset,
                        &calibration, &summary));
  ExpectExactSolution(rig, "fisheye", calibration, summary);
}

// Behind the camera, farther than 50 times the median depth, and on the
// ray of its observation but 10^-6 from the camera centre (it projects
// exactly, and its Jacobian is 10^12 times the others': a point collapsed
// onto a camera, as on EuRoC's map): all three rejected.
TEST(FinalBundleAdjusterTest, RejectsPointsBehindTooNearAndFarFromTheCamera) {
  SyntheticBaScene rig = MakeSyntheticRig(SceneOptions());
  RigImage& image = rig.dataset.images[0];
  const Rigid3d cam_from_world =
      rig.truth.CamFromWorld(image.camera_index, image.frameset_index);
  const Rigid3d world_from_cam = cam_from_world.Inverse();
  Correspondence behind = image.correspondences[0];
  behind.point3D = world_from_cam * Eigen::Vector3d(0.1, 0.2, -5);
  Correspondence far = image.correspondences[1];
  far.point3D = world_from_cam * Eigen::Vector3d(1000, 0, 5000);
  Correspondence near = image.correspondences[2];
  const Eigen::Vector3d in_cam = cam_from_world * near.point3D;
  near.point3D = world_from_cam * (in_cam * (1e-6 / in_cam.z()));
  image.correspondences.push_back(behind);
  image.correspondences.push_back(far);
  image.correspondences.push_back(near);
  rig.truth.images[0].inlier_mask.assign(image.correspondences.size(), 1);
  RigCalibration calibration = PerturbedStart(rig, 8);
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset,
                        &calibration, &summary));
  EXPECT_EQ(summary.num_outliers, 3);
  const std::vector<char>& mask = calibration.images[0].inlier_mask;
  EXPECT_FALSE(mask[mask.size() - 3]);
  EXPECT_FALSE(mask[mask.size() - 2]);
  EXPECT_FALSE(mask[mask.size() - 1]);
  EXPECT_TRUE(std::isfinite(summary.final_rms_px));
  EXPECT_LT(summary.final_rms_px, 1e-8);
}

TEST(FinalBundleAdjusterTest, UsesOnlyInliersOfPosedFramesetsAndCameras) {
  SyntheticBaScene rig = MakeSyntheticRig(SceneOptions());
  RigCalibration calibration = PerturbedStart(rig, 9);
  calibration.rig_from_world[1].reset();
  calibration.camera_calibrated[2] = false;
  // Gross outliers the mask already rejects never enter.
  RigImage& first = rig.dataset.images[0];
  first.correspondences[0].point2D += Eigen::Vector2d(100, -50);
  calibration.images[0].inlier_mask[0] = 0;
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset,
                        &calibration, &summary));
  EXPECT_LT(summary.final_rms_px, 1e-8);
  EXPECT_EQ(summary.num_outliers, 0);
  EXPECT_FALSE(calibration.images[0].inlier_mask[0]);
  EXPECT_FALSE(calibration.rig_from_world[1].has_value());
  for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
    const RigImage& image = rig.dataset.images[i];
    const bool expected_used =
        image.frameset_index != 1 && image.camera_index != 2;
    EXPECT_EQ(calibration.images[i].used, expected_used) << image.name;
  }
  // The uncalibrated camera keeps its parameters.
  EXPECT_EQ(calibration.cameras[2].Params(),
            PerturbedStart(rig, 9).cameras[2].Params());
}

TEST(FinalBundleAdjusterTest, RejectsInconsistentInput) {
  const SyntheticBaScene rig = MakeSyntheticRig(SceneOptions());
  RigCalibration calibration = PerturbedStart(rig, 10);
  RigCalibration bad = calibration;
  bad.rig_from_world.pop_back();
  EXPECT_FALSE(
      AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset, &bad, nullptr));
  bad = calibration;
  bad.images[0].inlier_mask.pop_back();
  EXPECT_FALSE(
      AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset, &bad, nullptr));
  bad = calibration;
  for (ImageResult& result : bad.images) {
    std::fill(result.inlier_mask.begin(), result.inlier_mask.end(), 0);
  }
  EXPECT_FALSE(
      AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset, &bad, nullptr));
  bad = calibration;
  bad.cameras[1].Params().pop_back();
  EXPECT_FALSE(
      AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset, &bad, nullptr));
  FinalBundleAdjustmentOptions options;
  options.loss_scale_px = 0;
  bad = calibration;
  EXPECT_FALSE(AdjustRig(options, rig.dataset, &bad, nullptr));
  // A failed call leaves the calibration as it was.
  EXPECT_EQ(bad.cameras[0].Params(), calibration.cameras[0].Params());
  EXPECT_FALSE(
      AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset, nullptr, nullptr));
}

// A benchmark rather than a test (run with --gtest_also_run_disabled_tests):
// 200 framesets x 10 cameras x 300 correspondences, 0.5 px noise, 5 %
// outliers.
TEST(FinalBundleAdjusterTest, DISABLED_LargeInstanceTiming) {
  SceneOptions scene;
  scene.num_cameras = 10;
  scene.num_framesets = 200;
  scene.num_points_per_image = 300;
  scene.noise_px = 0.5;
  scene.outlier_ratio = 0.05;
  const auto start = std::chrono::steady_clock::now();
  const SyntheticBaScene rig = MakeSyntheticRig(scene);
  RigCalibration calibration = PerturbedStart(rig, 11);
  std::printf(
      "scene made in %.2f s\n",
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count());
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset,
                        &calibration, &summary));
  PrintErrors("large", Compare(calibration, rig.truth), summary);
  std::printf("%s\n", summary.solver_report.c_str());
}

}  // namespace final_bundle_adjuster_test
}  // namespace rig_calibrator
