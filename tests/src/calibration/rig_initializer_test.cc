#include "src/calibration/rig_initializer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "tests/src/calibration/radial_rig_scene.h"

namespace rig_calibrator {
namespace {

using testing::MakeRadialRigScene;
using testing::RadialRigScene;
using testing::RadialRigSceneOptions;
using testing::RotationDistance;

// The truth in the radial gauge of the estimate (NormalizeRadialRigOrigin);
// its rotations and all radial projections are unchanged by that.
RigCalibration RadialTruth(const RadialRigScene& scene) {
  RigCalibration truth = scene.truth;
  NormalizeRadialRigOrigin(scene.dataset.reference_camera, &truth);
  return truth;
}

TEST(InitializeRig, ExactRadialPosesRecoverRig) {
  const RadialRigScene scene = MakeRadialRigScene(RadialRigSceneOptions());
  RigCalibration calibration = scene.input;
  RigInitializerSummary summary;
  ASSERT_TRUE(InitializeRig(RigInitializerOptions(), scene.dataset,
                            &calibration, &summary))
      << summary.message;
  EXPECT_EQ(summary.num_cameras_assigned, 5);
  EXPECT_EQ(summary.num_framesets_assigned, 30);
  EXPECT_EQ(summary.num_images_consistent, 150);
  EXPECT_LT(summary.best_score, 1e-6);

  const RigCalibration truth = RadialTruth(scene);
  EXPECT_EQ(
      (calibration.cam_from_rig[0].ToMatrix() - Rigid3d().ToMatrix()).norm(),
      0);
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(calibration.camera_calibrated[i]);
    const Rigid3d& estimate = calibration.cam_from_rig[i];
    EXPECT_LT(RotationDistance(estimate, truth.cam_from_rig[i]), 1e-8) << i;
    EXPECT_LT((estimate.translation - truth.cam_from_rig[i].translation).norm(),
              1e-8)
        << i;
    EXPECT_EQ(estimate.translation.z(), 0);
  }
  for (int j = 0; j < 30; ++j) {
    ASSERT_TRUE(calibration.rig_from_world[j]) << j;
    EXPECT_LT(RotationDistance(*calibration.rig_from_world[j],
                               *truth.rig_from_world[j]),
              1e-8);
    EXPECT_LT((calibration.rig_from_world[j]->translation -
               truth.rig_from_world[j]->translation)
                  .norm(),
              1e-8);
  }
  // Gauge-free check: the radial rows of every image's composed pose.
  for (const RigImage& image : scene.dataset.images) {
    const Eigen::Matrix<double, 3, 4> estimate =
        calibration.CamFromWorld(image.camera_index, image.frameset_index)
            .ToMatrix();
    const Eigen::Matrix<double, 3, 4> expected =
        scene.truth.CamFromWorld(image.camera_index, image.frameset_index)
            .ToMatrix();
    EXPECT_LT((estimate.topRows<2>() - expected.topRows<2>()).norm(), 1e-8);
  }
}

TEST(InitializeRig, FullPosesRecoverRigWithForwardTranslations) {
  RadialRigScene scene = MakeRadialRigScene(RadialRigSceneOptions());
  for (size_t k = 0; k < scene.dataset.images.size(); ++k) {
    const RigImage& image = scene.dataset.images[k];
    scene.input.images[k].single_image_cam_from_world =
        scene.truth.CamFromWorld(image.camera_index, image.frameset_index);
  }
  RigCalibration calibration = scene.input;
  RigInitializerOptions options;
  options.radial = false;
  RigInitializerSummary summary;
  ASSERT_TRUE(InitializeRig(options, scene.dataset, &calibration, &summary))
      << summary.message;
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(calibration.camera_calibrated[i]);
    EXPECT_LT((calibration.cam_from_rig[i].ToMatrix() -
               scene.truth.cam_from_rig[i].ToMatrix())
                  .norm(),
              1e-8)
        << i;
  }
  for (int j = 0; j < 30; ++j) {
    ASSERT_TRUE(calibration.rig_from_world[j]);
    EXPECT_LT((calibration.rig_from_world[j]->ToMatrix() -
               scene.truth.rig_from_world[j]->ToMatrix())
                  .norm(),
              1e-8);
  }
}

// Framesets of 2-3 cameras only, a fifth of the images mis-localized (their
// correspondences agree with their wrong poses), a tenth not localized,
// noisy poses and pixels.
RadialRigSceneOptions HardOptions() {
  RadialRigSceneOptions options;
  options.min_cameras_per_frameset = 2;
  options.max_cameras_per_frameset = 3;
  options.garbage_ratio = 0.2;
  options.missing_ratio = 0.1;
  options.noise_px = 0.5;
  options.pose_noise_deg = 0.05;
  options.pose_noise_translation = 0.002;
  options.seed = 7;
  return options;
}

TEST(InitializeRig, RobustToWrongAndMissingPosesWithoutCompleteFramesets) {
  const RadialRigScene scene = MakeRadialRigScene(HardOptions());
  int num_garbage = std::count(scene.garbage.begin(), scene.garbage.end(), 1);
  ASSERT_GE(num_garbage, 10);
  RigCalibration calibration = scene.input;
  RigInitializerSummary summary;
  ASSERT_TRUE(InitializeRig(RigInitializerOptions(), scene.dataset,
                            &calibration, &summary))
      << summary.message;
  EXPECT_EQ(summary.num_cameras_assigned, 5);

  const RigCalibration truth = RadialTruth(scene);
  double max_rotation_deg = 0, max_translation = 0;
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(calibration.camera_calibrated[i]);
    max_rotation_deg =
        std::max(max_rotation_deg,
                 RotationDifferenceDeg(calibration.cam_from_rig[i].rotation,
                                       truth.cam_from_rig[i].rotation));
    max_translation =
        std::max(max_translation, (calibration.cam_from_rig[i].translation -
                                   truth.cam_from_rig[i].translation)
                                      .norm());
  }
  EXPECT_LT(max_rotation_deg, 0.1);
  EXPECT_LT(max_translation, 0.02);

  // Framesets with two correctly localized images of non-parallel cameras
  // get an accurate rig pose; none of the others gets a wrong one.
  int num_determinable = 0, num_assigned = 0;
  for (int j = 0; j < 30; ++j) {
    int num_good = 0;
    for (size_t k = 0; k < scene.dataset.images.size(); ++k) {
      num_good += scene.dataset.images[k].frameset_index == j &&
                  scene.input.images[k].single_image_cam_from_world &&
                  !scene.garbage[k];
    }
    num_determinable += num_good >= 2;
    if (!calibration.rig_from_world[j]) continue;
    ++num_assigned;
    EXPECT_LT(RotationDifferenceDeg(calibration.rig_from_world[j]->rotation,
                                    truth.rig_from_world[j]->rotation),
              0.2)
        << j;
    EXPECT_LT((calibration.rig_from_world[j]->translation -
               truth.rig_from_world[j]->translation)
                  .norm(),
              0.05)
        << j;
  }
  EXPECT_GE(num_assigned, num_determinable - 1);
  EXPECT_LE(summary.num_trials, 30);
}

// The hard case on 40 random scenes: every run places the reference camera,
// every placed camera's rotation is accurate, and almost all cameras are
// placed. The ring's axes are nearly coplanar, and a frameset of two
// cameras constrains their offset only along the common normal of their
// axes (nearly vertical here): a camera seen only in pairs is weakly placed
// within the plane (translation errors of several cm) or, below the
// conditioning limit, left out.
TEST(InitializeRig, RobustAcrossRandomScenes) {
  int num_placed = 0;
  for (unsigned int seed = 1; seed <= 40; ++seed) {
    RadialRigSceneOptions scene_options = HardOptions();
    scene_options.seed = seed;
    const RadialRigScene scene = MakeRadialRigScene(scene_options);
    RigCalibration calibration = scene.input;
    RigInitializerSummary summary;
    ASSERT_TRUE(InitializeRig(RigInitializerOptions(), scene.dataset,
                              &calibration, &summary))
        << "scene " << seed << ": " << summary.message;
    num_placed += summary.num_cameras_assigned;
    const RigCalibration truth = RadialTruth(scene);
    for (int i = 0; i < 5; ++i) {
      if (!calibration.camera_calibrated[i]) continue;
      EXPECT_LT(RotationDifferenceDeg(calibration.cam_from_rig[i].rotation,
                                      truth.cam_from_rig[i].rotation),
                0.1)
          << "scene " << seed << " camera " << i;
      EXPECT_LT((calibration.cam_from_rig[i].translation -
                 truth.cam_from_rig[i].translation)
                    .norm(),
                0.15)
          << "scene " << seed << " camera " << i;
    }
    for (int j = 0; j < 30; ++j) {
      if (!calibration.rig_from_world[j]) continue;
      EXPECT_LT(RotationDifferenceDeg(calibration.rig_from_world[j]->rotation,
                                      truth.rig_from_world[j]->rotation),
                0.2)
          << "scene " << seed << " frameset " << j;
    }
  }
  EXPECT_GE(num_placed, 195);
}

// Camera 4 is only ever localized together with camera 0 alone: it can
// slide along camera 0's axis without changing any radial projection, so it
// must be left out rather than placed arbitrarily.
TEST(InitializeRig, CameraSeenWithOnlyOnePartnerIsNotPlaced) {
  RadialRigScene scene = MakeRadialRigScene(RadialRigSceneOptions());
  for (size_t k = 0; k < scene.dataset.images.size(); ++k) {
    const RigImage& image = scene.dataset.images[k];
    const bool with_camera_4 = image.frameset_index >= 15;
    if ((with_camera_4 && image.camera_index != 0 && image.camera_index != 4) ||
        (!with_camera_4 && image.camera_index == 4)) {
      scene.input.images[k].single_image_cam_from_world.reset();
    }
  }
  RigCalibration calibration = scene.input;
  RigInitializerSummary summary;
  ASSERT_TRUE(InitializeRig(RigInitializerOptions(), scene.dataset,
                            &calibration, &summary))
      << summary.message;
  EXPECT_EQ(summary.num_cameras_assigned, 4);
  EXPECT_FALSE(calibration.camera_calibrated[4]);
  const RigCalibration truth = RadialTruth(scene);
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(calibration.camera_calibrated[i]);
    EXPECT_LT(
        RotationDistance(calibration.cam_from_rig[i], truth.cam_from_rig[i]),
        1e-8);
  }

  // With full poses the pairs do place it.
  for (size_t k = 0; k < scene.dataset.images.size(); ++k) {
    if (scene.input.images[k].single_image_cam_from_world) {
      const RigImage& image = scene.dataset.images[k];
      scene.input.images[k].single_image_cam_from_world =
          scene.truth.CamFromWorld(image.camera_index, image.frameset_index);
    }
  }
  calibration = scene.input;
  RigInitializerOptions options;
  options.radial = false;
  ASSERT_TRUE(InitializeRig(options, scene.dataset, &calibration, &summary))
      << summary.message;
  ASSERT_TRUE(calibration.camera_calibrated[4]);
  EXPECT_LT((calibration.cam_from_rig[4].ToMatrix() -
             scene.truth.cam_from_rig[4].ToMatrix())
                .norm(),
            1e-8);
}

TEST(InitializeRig, DeterministicForSeed) {
  const RadialRigScene scene = MakeRadialRigScene(HardOptions());
  RigInitializerOptions options;
  options.seed = 3;
  RigCalibration first = scene.input;
  RigCalibration second = scene.input;
  ASSERT_TRUE(InitializeRig(options, scene.dataset, &first, nullptr));
  ASSERT_TRUE(InitializeRig(options, scene.dataset, &second, nullptr));
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(first.cam_from_rig[i].ToMatrix(),
              second.cam_from_rig[i].ToMatrix());
  }
  for (int j = 0; j < 30; ++j) {
    ASSERT_EQ(first.rig_from_world[j].has_value(),
              second.rig_from_world[j].has_value());
    if (first.rig_from_world[j]) {
      EXPECT_EQ(first.rig_from_world[j]->ToMatrix(),
                second.rig_from_world[j]->ToMatrix());
    }
  }
}

TEST(InitializeRig, StereoPairWithParallelAxesIsRejected) {
  RadialRigSceneOptions scene_options;
  scene_options.stereo = true;
  scene_options.min_cameras_per_frameset = 2;
  scene_options.max_cameras_per_frameset = 2;
  const RadialRigScene scene = MakeRadialRigScene(scene_options);

  std::string explanation;
  EXPECT_TRUE(
      PrincipalAxesAreParallel(scene.dataset, scene.input, 5.0, &explanation));
  EXPECT_NE(explanation.find("parallel"), std::string::npos) << explanation;

  RigCalibration calibration = scene.input;
  RigInitializerSummary summary;
  EXPECT_FALSE(InitializeRig(RigInitializerOptions(), scene.dataset,
                             &calibration, &summary));
  EXPECT_NE(summary.message.find("parallel"), std::string::npos)
      << summary.message;
  EXPECT_NE(summary.message.find("rd_ra"), std::string::npos)
      << summary.message;

  // Full per-image poses do determine a parallel rig.
  RigCalibration full = scene.input;
  for (size_t k = 0; k < scene.dataset.images.size(); ++k) {
    const RigImage& image = scene.dataset.images[k];
    full.images[k].single_image_cam_from_world =
        scene.truth.CamFromWorld(image.camera_index, image.frameset_index);
  }
  RigInitializerOptions full_options;
  full_options.radial = false;
  ASSERT_TRUE(InitializeRig(full_options, scene.dataset, &full, &summary))
      << summary.message;
  EXPECT_LT(
      (full.cam_from_rig[1].ToMatrix() - scene.truth.cam_from_rig[1].ToMatrix())
          .norm(),
      1e-8);
}

TEST(PrincipalAxesAreParallel, RingIsNotParallel) {
  const RadialRigScene scene = MakeRadialRigScene(HardOptions());
  std::string explanation;
  EXPECT_FALSE(
      PrincipalAxesAreParallel(scene.dataset, scene.input, 5.0, &explanation));
  EXPECT_NE(explanation.find("not parallel"), std::string::npos) << explanation;
}

TEST(PrincipalAxesAreParallel, NoPairOfLocalizedImages) {
  RadialRigScene scene = MakeRadialRigScene(RadialRigSceneOptions());
  for (size_t k = 0; k < scene.dataset.images.size(); ++k) {
    if (scene.dataset.images[k].camera_index != 0) {
      scene.input.images[k].single_image_cam_from_world.reset();
    }
  }
  std::string explanation;
  EXPECT_FALSE(
      PrincipalAxesAreParallel(scene.dataset, scene.input, 5.0, &explanation));
  EXPECT_NE(explanation.find("cannot be compared"), std::string::npos)
      << explanation;
}

TEST(InitializeRig, UnplaceableReferenceCameraFails) {
  RadialRigScene scene = MakeRadialRigScene(RadialRigSceneOptions());
  for (size_t k = 0; k < scene.dataset.images.size(); ++k) {
    if (scene.dataset.images[k].camera_index == 2) {
      scene.input.images[k].single_image_cam_from_world.reset();
      scene.input.images[k].inlier_mask.clear();
    }
  }
  scene.dataset.reference_camera = 2;
  RigCalibration calibration = scene.input;
  RigInitializerSummary summary;
  EXPECT_FALSE(InitializeRig(RigInitializerOptions(), scene.dataset,
                             &calibration, &summary));
  EXPECT_NE(summary.message.find("reference camera cam2"), std::string::npos)
      << summary.message;
}

TEST(InitializeRig, NonReferenceCameraWithoutImagesIsNotCalibrated) {
  RadialRigScene scene = MakeRadialRigScene(RadialRigSceneOptions());
  for (size_t k = 0; k < scene.dataset.images.size(); ++k) {
    if (scene.dataset.images[k].camera_index == 3) {
      scene.input.images[k].single_image_cam_from_world.reset();
    }
  }
  RigCalibration calibration = scene.input;
  RigInitializerSummary summary;
  ASSERT_TRUE(InitializeRig(RigInitializerOptions(), scene.dataset,
                            &calibration, &summary))
      << summary.message;
  EXPECT_EQ(summary.num_cameras_assigned, 4);
  EXPECT_FALSE(calibration.camera_calibrated[3]);
  EXPECT_TRUE(calibration.camera_calibrated[4]);
}

TEST(InitializeRig, InconsistentInputFails) {
  const RadialRigScene scene = MakeRadialRigScene(RadialRigSceneOptions());
  RigInitializerSummary summary;
  RigCalibration calibration = scene.input;
  calibration.images.pop_back();
  EXPECT_FALSE(InitializeRig(RigInitializerOptions(), scene.dataset,
                             &calibration, &summary));
  EXPECT_NE(summary.message.find("image results"), std::string::npos);

  calibration = scene.input;
  calibration.images[3].inlier_mask.resize(2);
  EXPECT_FALSE(InitializeRig(RigInitializerOptions(), scene.dataset,
                             &calibration, &summary));
  EXPECT_NE(summary.message.find("inlier mask"), std::string::npos);

  RigDataset duplicated = scene.dataset;
  duplicated.images[1].camera_index = duplicated.images[0].camera_index;
  calibration = scene.input;
  EXPECT_FALSE(InitializeRig(RigInitializerOptions(), duplicated, &calibration,
                             &summary));
  EXPECT_NE(summary.message.find("both localized"), std::string::npos);

  calibration = scene.input;
  calibration.images[0].single_image_cam_from_world->translation.x() = NAN;
  EXPECT_FALSE(InitializeRig(RigInitializerOptions(), scene.dataset,
                             &calibration, &summary));
  EXPECT_NE(summary.message.find("non-finite"), std::string::npos);
}

TEST(NormalizeRadialRigOrigin, KeepsRadialProjectionsAndIsIdempotent) {
  const RadialRigScene scene = MakeRadialRigScene(RadialRigSceneOptions());
  RigCalibration normalized = scene.truth;
  NormalizeRadialRigOrigin(0, &normalized);
  for (const RigImage& image : scene.dataset.images) {
    const Eigen::Matrix<double, 3, 4> before =
        scene.truth.CamFromWorld(image.camera_index, image.frameset_index)
            .ToMatrix();
    const Eigen::Matrix<double, 3, 4> after =
        normalized.CamFromWorld(image.camera_index, image.frameset_index)
            .ToMatrix();
    EXPECT_LT((before.topRows<2>() - after.topRows<2>()).norm(), 1e-12);
  }
  // The origin is already the point of the reference axis closest to the
  // other axes: sum_i g_i . t_i,xy = 0.
  double moment = 0;
  for (int i = 1; i < 5; ++i) {
    const Rigid3d& cam_from_rig = normalized.cam_from_rig[i];
    EXPECT_EQ(cam_from_rig.translation.z(), 0);
    moment += cam_from_rig.RotationMatrix().col(2).head<2>().dot(
        cam_from_rig.translation.head<2>());
  }
  EXPECT_LT(std::abs(moment), 1e-12);
  RigCalibration twice = normalized;
  NormalizeRadialRigOrigin(0, &twice);
  for (int i = 0; i < 5; ++i) {
    EXPECT_LT((twice.cam_from_rig[i].translation -
               normalized.cam_from_rig[i].translation)
                  .norm(),
              1e-12);
  }
}

}  // namespace
}  // namespace rig_calibrator
