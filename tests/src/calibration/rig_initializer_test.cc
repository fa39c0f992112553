#include "src/calibration/rig_initializer.h"

#include <colmap/util/math.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "tests/src/calibration/radial_rig_scene.h"

namespace rig_calibrator {
namespace testing {
namespace rig_initializer_test {

// InitializeRig on a copy of the scene's input; fails with its message.
::testing::AssertionResult Initialize(const RadialRigScene& scene,
                                      const RigInitializerOptions& options,
                                      RigCalibration* calibration,
                                      RigInitializerSummary* summary) {
  *calibration = scene.input;
  if (InitializeRig(options, scene.dataset, calibration, summary)) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << summary->message;
}

// Initializes the scene's rig (radial poses), expecting every camera but
// `left_out` to be placed.
void InitializeWithoutCamera(const RadialRigScene& scene, int left_out,
                             RigCalibration* calibration) {
  RigInitializerSummary summary;
  ASSERT_TRUE(
      Initialize(scene, RigInitializerOptions(), calibration, &summary));
  EXPECT_EQ(summary.num_cameras_assigned, 4);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(calibration->camera_calibrated[i], i != left_out) << i;
  }
}

RigInitializerOptions FullPoseOptions() {
  RigInitializerOptions options;
  options.radial = false;
  return options;
}

TEST(InitializeRig, ExactRadialPosesRecoverRig) {
  const RadialRigScene scene = MakeRadialRigScene(RadialRigSceneOptions());
  RigCalibration calibration;
  RigInitializerSummary summary;
  ASSERT_TRUE(
      Initialize(scene, RigInitializerOptions(), &calibration, &summary));
  EXPECT_EQ(summary.num_cameras_assigned, 5);
  EXPECT_EQ(summary.num_framesets_assigned, 30);
  EXPECT_EQ(summary.num_images_consistent, 150);
  EXPECT_LT(summary.best_score, 1e-6);

  EXPECT_EQ(calibration.cam_from_rig[0].ToMatrix(), Rigid3d().ToMatrix());
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(calibration.cam_from_rig[i].translation.z(), 0);
  }
  ExpectRigNear(calibration, RadialTruth(scene), 1e-8);
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
  UseTrueFullPoses(&scene);
  RigCalibration calibration;
  RigInitializerSummary summary;
  ASSERT_TRUE(Initialize(scene, FullPoseOptions(), &calibration, &summary));
  // The forward translations are recovered too: no radial gauge.
  ExpectRigNear(calibration, scene.truth, 1e-8);
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
  RigCalibration calibration;
  RigInitializerSummary summary;
  ASSERT_TRUE(
      Initialize(scene, RigInitializerOptions(), &calibration, &summary));
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
  std::vector<double> translation_errors;
  for (unsigned int seed = 1; seed <= 40; ++seed) {
    SCOPED_TRACE("scene " + std::to_string(seed));
    RadialRigSceneOptions scene_options = HardOptions();
    scene_options.seed = seed;
    const RadialRigScene scene = MakeRadialRigScene(scene_options);
    RigCalibration calibration;
    RigInitializerSummary summary;
    ASSERT_TRUE(
        Initialize(scene, RigInitializerOptions(), &calibration, &summary));
    num_placed += summary.num_cameras_assigned;
    const RigCalibration truth = RadialTruth(scene);
    for (int i = 0; i < 5; ++i) {
      if (!calibration.camera_calibrated[i]) continue;
      EXPECT_LT(RotationDifferenceDeg(calibration.cam_from_rig[i].rotation,
                                      truth.cam_from_rig[i].rotation),
                0.1)
          << "scene " << seed << " camera " << i;
      translation_errors.push_back((calibration.cam_from_rig[i].translation -
                                    truth.cam_from_rig[i].translation)
                                       .norm());
      EXPECT_LT(translation_errors.back(), 0.12)
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
  // Most cameras are placed to a few mm (median 2.6 mm when written).
  EXPECT_LT(colmap::Median(translation_errors), 0.01);
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
  RigCalibration calibration;
  ASSERT_NO_FATAL_FAILURE(InitializeWithoutCamera(scene, 4, &calibration));
  // The radial gauge of the estimate is fixed by the placed cameras only.
  RigCalibration truth = scene.truth;
  truth.camera_calibrated[4] = false;
  NormalizeRadialRigOrigin(0, &truth);
  for (int i = 0; i < 4; ++i) {
    EXPECT_LT(
        RotationDistance(calibration.cam_from_rig[i], truth.cam_from_rig[i]),
        1e-8);
    EXPECT_LT((calibration.cam_from_rig[i].translation -
               truth.cam_from_rig[i].translation)
                  .norm(),
              1e-8);
  }

  // With full poses the pairs do place it.
  UseTrueFullPoses(&scene);
  RigInitializerSummary summary;
  ASSERT_TRUE(Initialize(scene, FullPoseOptions(), &calibration, &summary));
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

// Two cameras whose axes are turned by yaw_deg: 1D radial poses cannot fix
// the rig of a (nearly) parallel or anti-parallel pair, the radial
// initialization says so (not that the reference camera cannot be placed),
// and full per-image poses do fix it.
void ExpectPairRejectedByRadialAndFixedByFullPoses(double yaw_deg) {
  SCOPED_TRACE("pair yaw " + std::to_string(yaw_deg) + " degrees");
  RadialRigScene scene = MakePairScene(yaw_deg);

  RigCalibration calibration = scene.input;
  RigInitializerSummary summary;
  EXPECT_FALSE(InitializeRig(RigInitializerOptions(), scene.dataset,
                             &calibration, &summary));
  EXPECT_NE(summary.message.find("parallel or anti-parallel"),
            std::string::npos)
      << summary.message;
  EXPECT_NE(summary.message.find("rd_ra"), std::string::npos)
      << summary.message;

  UseTrueFullPoses(&scene);
  ASSERT_TRUE(Initialize(scene, FullPoseOptions(), &calibration, &summary));
  ExpectRigNear(calibration, scene.truth, 1e-8);
}

TEST(InitializeRig, StereoPairWithParallelAxesIsRejected) {
  ExpectPairRejectedByRadialAndFixedByFullPoses(0);
}

TEST(InitializeRig, FrontBackPairWithAntiParallelAxesIsRejected) {
  ExpectPairRejectedByRadialAndFixedByFullPoses(180);
}

// Near-anti-parallel is as degenerate as near-parallel.
TEST(InitializeRig, NearAntiParallelPairIsRejectedLikeNearParallel) {
  ExpectPairRejectedByRadialAndFixedByFullPoses(2);
  ExpectPairRejectedByRadialAndFixedByFullPoses(178);
}

// Well apart from (anti-)parallel, a radial pair is initialized: each
// frameset's two axes determine its rig pose. (The other camera's position
// along the reference axis is the radial gauge, RadialTruth.)
TEST(InitializeRig, PairAtRightAnglesIsInitializedFromRadialPoses) {
  for (const double yaw_deg : {90.0, 135.0}) {
    SCOPED_TRACE("pair yaw " + std::to_string(yaw_deg) + " degrees");
    const RadialRigScene scene = MakePairScene(yaw_deg);
    RigCalibration calibration;
    RigInitializerSummary summary;
    ASSERT_TRUE(
        Initialize(scene, RigInitializerOptions(), &calibration, &summary));
    ExpectRigNear(calibration, RadialTruth(scene), 1e-8);
  }
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
  RigCalibration calibration;
  ASSERT_NO_FATAL_FAILURE(InitializeWithoutCamera(scene, 3, &calibration));
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

}  // namespace rig_initializer_test
}  // namespace testing
}  // namespace rig_calibrator
