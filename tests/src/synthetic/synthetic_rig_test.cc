#include "src/synthetic/synthetic_rig.h"

#include <colmap/base/camera_models.h>
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

namespace rig_calibrator {
namespace synthetic_rig_test {

// Pixel error of a correspondence under the true calibration; infinity when
// the 3D point is behind the camera.
double TrueReprojectionError(const SyntheticRig& rig, const RigImage& image,
                             const Correspondence& correspondence,
                             Eigen::Vector2d* residual = nullptr) {
  const Rigid3d cam_from_world = rig.truth.cam_from_rig[image.camera_index] *
                                 rig.truth.rig_from_world[image.frameset_index];
  const Eigen::Vector3d point = cam_from_world * correspondence.point3D;
  if (point.z() <= 0) {
    return std::numeric_limits<double>::infinity();
  }
  const Eigen::Vector2d projected =
      rig.truth.cameras[image.camera_index].WorldToImage(point.hnormalized());
  if (residual != nullptr) {
    *residual = correspondence.point2D - projected;
  }
  return (correspondence.point2D - projected).norm();
}

SyntheticRigOptions SmallOptions(RigPreset preset) {
  SyntheticRigOptions options;
  options.preset = preset;
  options.num_framesets = 12;
  options.points_per_image = 100;
  options.seed = 7;
  return options;
}

TEST(SyntheticRig, PresetsMatchTheirDescription) {
  const std::map<RigPreset, std::vector<std::string>> models = {
      {RigPreset::kRing5, {"OPENCV", "OPENCV", "OPENCV", "OPENCV", "OPENCV"}},
      {RigPreset::kFisheyeHelmet5,
       std::vector<std::string>(5, "OPENCV_FISHEYE")},
      {RigPreset::kCarSurround4,
       {"OPENCV", "OPENCV_FISHEYE", "RADIAL", "OPENCV_FISHEYE"}},
      {RigPreset::kStereoPair, {"OPENCV", "OPENCV"}}};
  for (const auto& [preset, model_names] : models) {
    SCOPED_TRACE(RigPresetName(preset));
    const RigGroundTruth truth = MakeRigPreset(preset);
    ASSERT_EQ(truth.cameras.size(), model_names.size());
    ASSERT_EQ(truth.cam_from_rig.size(), model_names.size());
    EXPECT_TRUE(truth.rig_from_world.empty());
    EXPECT_TRUE(truth.cam_from_rig[0].rotation.isApprox(
        Eigen::Quaterniond::Identity(), 1e-15));
    EXPECT_EQ(truth.cam_from_rig[0].translation.norm(), 0.0);
    for (size_t i = 0; i < model_names.size(); ++i) {
      EXPECT_EQ(truth.cameras[i].ModelName(), model_names[i]);
      EXPECT_TRUE(truth.cameras[i].VerifyParams());
      EXPECT_EQ(truth.camera_names[i], "cam" + std::to_string(i));
    }
  }
  // Ring: 0.15 m radius, neighbours 72 degrees apart.
  const RigGroundTruth ring = MakeRigPreset(RigPreset::kRing5);
  for (int i = 1; i < 5; ++i) {
    const double distance = ring.cam_from_rig[i].Center().norm();
    EXPECT_NEAR(distance, 2 * 0.15 * std::sin(M_PI * i / 5), 0.02);
    const double angle = RotationDifferenceDeg(ring.cam_from_rig[0].rotation,
                                               ring.cam_from_rig[i].rotation);
    EXPECT_NEAR(angle, std::min(72.0 * i, 360 - 72.0 * i), 6.0);
    EXPECT_NEAR(ring.cameras[i].PrincipalPointX(), 320, 20);
    EXPECT_NEAR(ring.cameras[i].PrincipalPointY(), 240, 20);
  }
  // Stereo: 0.11 m baseline along x, nearly parallel axes.
  const RigGroundTruth stereo = MakeRigPreset(RigPreset::kStereoPair);
  EXPECT_NEAR(stereo.cam_from_rig[1].translation.x(), -0.11, 1e-3);
  EXPECT_NEAR(stereo.cam_from_rig[1].Center().norm(), 0.11, 1e-3);
  EXPECT_LT(RotationDifferenceDeg(stereo.cam_from_rig[1].rotation,
                                  Eigen::Quaterniond::Identity()),
            0.3);
  // Fisheye helmet: the image half-diagonal (400 px) maps to 72.5-77.5
  // degrees off the axis.
  const RigGroundTruth helmet = MakeRigPreset(RigPreset::kFisheyeHelmet5);
  for (const colmap::Camera& camera : helmet.cameras) {
    const Eigen::Vector2d corner(camera.PrincipalPointX() + 320,
                                 camera.PrincipalPointY() + 240);
    const double angle_deg =
        std::atan(camera.ImageToWorld(corner).norm()) * 180 / M_PI;
    EXPECT_GT(angle_deg, 72);
    EXPECT_LT(angle_deg, 78);
  }
}

TEST(SyntheticRig, InitialCamerasAreCenteredWithoutDistortion) {
  const SyntheticRig rig =
      GenerateSyntheticRig(SmallOptions(RigPreset::kCarSurround4));
  ASSERT_EQ(rig.dataset.cameras.size(), 4);
  for (size_t c = 0; c < rig.dataset.cameras.size(); ++c) {
    const colmap::Camera& camera = rig.dataset.cameras[c].camera;
    const colmap::Camera& truth = rig.truth.cameras[c];
    EXPECT_EQ(rig.dataset.cameras[c].name, "cam" + std::to_string(c));
    EXPECT_FALSE(rig.dataset.cameras[c].intrinsics_known);
    EXPECT_EQ(camera.ModelId(), truth.ModelId());
    EXPECT_EQ(camera.Width(), truth.Width());
    EXPECT_EQ(camera.Height(), truth.Height());
    EXPECT_EQ(camera.PrincipalPointX(), 0.5 * truth.Width());
    EXPECT_EQ(camera.PrincipalPointY(), 0.5 * truth.Height());
    EXPECT_EQ(camera.MeanFocalLength(),
              1.2 * std::max(truth.Width(), truth.Height()));
    for (const size_t idx : camera.ExtraParamsIdxs()) {
      EXPECT_EQ(camera.Params()[idx], 0.0);
    }
  }
  EXPECT_EQ(rig.dataset.reference_camera, 0);
}

TEST(SyntheticRig, DeterministicForSeed) {
  const SyntheticRigOptions options = SmallOptions(RigPreset::kRing5);
  const SyntheticRig a = GenerateSyntheticRig(options);
  const SyntheticRig b = GenerateSyntheticRig(options);
  ASSERT_EQ(a.dataset.images.size(), b.dataset.images.size());
  ASSERT_FALSE(a.dataset.images.empty());
  for (size_t i = 0; i < a.dataset.images.size(); ++i) {
    const RigImage& image_a = a.dataset.images[i];
    const RigImage& image_b = b.dataset.images[i];
    EXPECT_EQ(image_a.name, image_b.name);
    ASSERT_EQ(image_a.correspondences.size(), image_b.correspondences.size());
    for (size_t k = 0; k < image_a.correspondences.size(); ++k) {
      EXPECT_EQ(image_a.correspondences[k].point2D,
                image_b.correspondences[k].point2D);
      EXPECT_EQ(image_a.correspondences[k].point3D,
                image_b.correspondences[k].point3D);
      EXPECT_EQ(image_a.correspondences[k].point3D_id,
                image_b.correspondences[k].point3D_id);
    }
    EXPECT_EQ(a.is_outlier[i], b.is_outlier[i]);
  }
  for (size_t j = 0; j < a.truth.rig_from_world.size(); ++j) {
    EXPECT_EQ(a.truth.rig_from_world[j].translation,
              b.truth.rig_from_world[j].translation);
  }

  SyntheticRigOptions other_options = options;
  other_options.seed = 8;
  const SyntheticRig c = GenerateSyntheticRig(other_options);
  EXPECT_NE(a.dataset.images[0].correspondences[0].point2D,
            c.dataset.images[0].correspondences[0].point2D);
  EXPECT_NE(a.truth.rig_from_world[5].translation,
            c.truth.rig_from_world[5].translation);
}

TEST(SyntheticRig, NamesAndIndices) {
  const SyntheticRig rig =
      GenerateSyntheticRig(SmallOptions(RigPreset::kRing5));
  ASSERT_EQ(rig.dataset.frameset_names.size(), 12);
  EXPECT_EQ(rig.dataset.frameset_names[7], "000007");
  EXPECT_EQ(rig.truth.rig_from_world.size(), 12);
  ASSERT_EQ(rig.is_outlier.size(), rig.dataset.images.size());
  std::set<std::string> names;
  for (const RigImage& image : rig.dataset.images) {
    EXPECT_EQ(image.name, "cam" + std::to_string(image.camera_index) + "/" +
                              rig.dataset.frameset_names[image.frameset_index] +
                              ".png");
    names.insert(image.name);
  }
  EXPECT_EQ(names.size(), rig.dataset.images.size());
}

TEST(SyntheticRig, ExactDataReprojectsAndOutliersAreWrong) {
  for (const RigPreset preset : AllRigPresets()) {
    SCOPED_TRACE(RigPresetName(preset));
    SyntheticRigOptions options = SmallOptions(preset);
    options.noise_px = 0;
    const SyntheticRig rig = GenerateSyntheticRig(options);
    ASSERT_FALSE(rig.dataset.images.empty());
    double max_inlier_error = 0;
    double min_outlier_error = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
      const RigImage& image = rig.dataset.images[i];
      for (size_t k = 0; k < image.correspondences.size(); ++k) {
        const double error =
            TrueReprojectionError(rig, image, image.correspondences[k]);
        if (rig.is_outlier[i][k]) {
          min_outlier_error = std::min(min_outlier_error, error);
        } else {
          max_inlier_error = std::max(max_inlier_error, error);
        }
      }
    }
    EXPECT_LT(max_inlier_error, 1e-9);
    EXPECT_GT(min_outlier_error, 20.0);
  }
}

TEST(SyntheticRig, NoiseHasTheRequestedStatistics) {
  SyntheticRigOptions options = SmallOptions(RigPreset::kFisheyeHelmet5);
  options.noise_px = 0.5;
  options.points_per_image = 200;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  double sum_x = 0, sum_y = 0, sum_squares = 0;
  int count = 0;
  for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
    const RigImage& image = rig.dataset.images[i];
    for (size_t k = 0; k < image.correspondences.size(); ++k) {
      if (rig.is_outlier[i][k]) {
        continue;
      }
      Eigen::Vector2d residual = Eigen::Vector2d::Zero();
      TrueReprojectionError(rig, image, image.correspondences[k], &residual);
      sum_x += residual.x();
      sum_y += residual.y();
      sum_squares += residual.squaredNorm();
      ++count;
    }
  }
  ASSERT_GT(count, 5000);
  const double per_coordinate_rms = std::sqrt(sum_squares / (2 * count));
  EXPECT_NEAR(per_coordinate_rms, 0.5, 0.5 * 0.03);
  EXPECT_NEAR(sum_x / count, 0, 0.02);
  EXPECT_NEAR(sum_y / count, 0, 0.02);
}

TEST(SyntheticRig, OutlierAndMissingRatiosAreAsAsked) {
  SyntheticRigOptions options = SmallOptions(RigPreset::kRing5);
  options.num_framesets = 20;
  options.outlier_ratio = 0.3;
  options.missing_image_ratio = 0.1;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  const int total_images = 20 * 5;
  EXPECT_EQ(rig.dataset.images.size(), total_images - 10);
  std::vector<int> images_per_frameset(20, 0);
  int num_outliers = 0, num_correspondences = 0;
  for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
    ++images_per_frameset[rig.dataset.images[i].frameset_index];
    EXPECT_EQ(rig.dataset.images[i].correspondences.size(), 100);
    for (const char outlier : rig.is_outlier[i]) {
      num_outliers += outlier;
    }
    num_correspondences += rig.is_outlier[i].size();
  }
  EXPECT_NEAR(static_cast<double>(num_outliers) / num_correspondences, 0.3,
              0.005);
  for (const int count : images_per_frameset) {
    EXPECT_GE(count, 1);
  }

  // Stereo with 40% missing: no frameset may lose both images.
  SyntheticRigOptions stereo_options = SmallOptions(RigPreset::kStereoPair);
  stereo_options.num_framesets = 20;
  stereo_options.missing_image_ratio = 0.4;
  stereo_options.outlier_ratio = 0;
  const SyntheticRig stereo = GenerateSyntheticRig(stereo_options);
  EXPECT_EQ(stereo.dataset.images.size(), 40 - 16);
  std::set<int> framesets;
  for (size_t i = 0; i < stereo.dataset.images.size(); ++i) {
    framesets.insert(stereo.dataset.images[i].frameset_index);
    for (const char outlier : stereo.is_outlier[i]) {
      EXPECT_EQ(outlier, 0);
    }
  }
  EXPECT_EQ(framesets.size(), 20);
}

TEST(SyntheticRig, PointsAreInsideImagesAndWithinDepthRange) {
  for (const RigPreset preset : AllRigPresets()) {
    SCOPED_TRACE(RigPresetName(preset));
    SyntheticRigOptions options = SmallOptions(preset);
    options.noise_px = 2.0;
    options.min_depth = 3.0;
    options.max_depth = 8.0;
    const SyntheticRig rig = GenerateSyntheticRig(options);
    for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
      const RigImage& image = rig.dataset.images[i];
      const colmap::Camera& camera = rig.truth.cameras[image.camera_index];
      const Rigid3d cam_from_world =
          rig.truth.cam_from_rig[image.camera_index] *
          rig.truth.rig_from_world[image.frameset_index];
      for (size_t k = 0; k < image.correspondences.size(); ++k) {
        const Eigen::Vector2d& xy = image.correspondences[k].point2D;
        EXPECT_GE(xy.x(), 0);
        EXPECT_GE(xy.y(), 0);
        EXPECT_LE(xy.x(), camera.Width());
        EXPECT_LE(xy.y(), camera.Height());
        if (!rig.is_outlier[i][k]) {
          const double distance =
              (cam_from_world * image.correspondences[k].point3D).norm();
          EXPECT_GE(distance, 3.0 - 1e-9);
          EXPECT_LE(distance, 8.0 + 1e-9);
        }
      }
    }
  }
}

// The whole image is covered, including the fisheye periphery: points beyond
// 0.9 of the half-diagonal from the center, and in every image quadrant.
TEST(SyntheticRig, FisheyePeripheryIsCovered) {
  SyntheticRigOptions options = SmallOptions(RigPreset::kFisheyeHelmet5);
  options.noise_px = 0;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  std::vector<int> peripheral(5, 0);
  std::vector<std::set<int>> quadrants(5);
  for (const RigImage& image : rig.dataset.images) {
    const colmap::Camera& camera = rig.truth.cameras[image.camera_index];
    const Eigen::Vector2d center(0.5 * camera.Width(), 0.5 * camera.Height());
    const double half_diagonal =
        0.5 * std::hypot(camera.Width(), camera.Height());
    for (const Correspondence& correspondence : image.correspondences) {
      const Eigen::Vector2d offset = correspondence.point2D - center;
      if (offset.norm() > 0.9 * half_diagonal) {
        ++peripheral[image.camera_index];
        quadrants[image.camera_index].insert((offset.x() > 0) +
                                             2 * (offset.y() > 0));
      }
    }
  }
  for (int c = 0; c < 5; ++c) {
    EXPECT_GE(peripheral[c], 5) << "camera " << c;
    EXPECT_EQ(quadrants[c].size(), 4) << "camera " << c;
  }
}

TEST(SyntheticRig, MapPointsAreSharedAcrossImages) {
  SyntheticRigOptions options = SmallOptions(RigPreset::kRing5);
  options.track_ratio = 0.5;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  std::map<int64_t, int> observations;
  std::map<int64_t, Eigen::Vector3d> positions;
  int num_inliers = 0;
  for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
    std::set<int64_t> ids_in_image;
    const RigImage& image = rig.dataset.images[i];
    for (size_t k = 0; k < image.correspondences.size(); ++k) {
      const Correspondence& correspondence = image.correspondences[k];
      ASSERT_GE(correspondence.point3D_id, 0);
      EXPECT_TRUE(ids_in_image.insert(correspondence.point3D_id).second)
          << "point observed twice in " << image.name;
      const auto [it, inserted] =
          positions.emplace(correspondence.point3D_id, correspondence.point3D);
      EXPECT_EQ(it->second, correspondence.point3D);
      if (!rig.is_outlier[i][k]) {
        ++observations[correspondence.point3D_id];
        ++num_inliers;
      }
    }
  }
  int num_tracked = 0;
  for (const auto& [id, count] : observations) {
    if (count > 1) {
      num_tracked += count;
    }
  }
  // Half of the correct matches re-observe earlier points; the first
  // frameset has none to re-observe.
  EXPECT_GT(static_cast<double>(num_tracked) / num_inliers, 0.4);

  options.track_ratio = 0;
  const SyntheticRig untracked = GenerateSyntheticRig(options);
  std::set<int64_t> inlier_ids;
  int count = 0;
  for (size_t i = 0; i < untracked.dataset.images.size(); ++i) {
    for (size_t k = 0; k < untracked.is_outlier[i].size(); ++k) {
      if (!untracked.is_outlier[i][k]) {
        inlier_ids.insert(
            untracked.dataset.images[i].correspondences[k].point3D_id);
        ++count;
      }
    }
  }
  EXPECT_EQ(inlier_ids.size(), count);
}

TEST(SyntheticRig, NearPlanarPointsLieOnTheGround) {
  SyntheticRigOptions options = SmallOptions(RigPreset::kCarSurround4);
  options.near_planar_ratio = 0.5;
  options.outlier_ratio = 0;
  options.track_ratio = 0;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  int on_ground = 0, total = 0;
  for (const RigImage& image : rig.dataset.images) {
    for (const Correspondence& correspondence : image.correspondences) {
      on_ground += std::abs(correspondence.point3D.z()) < 1e-9;
      ++total;
    }
  }
  EXPECT_NEAR(static_cast<double>(on_ground) / total, 0.5, 0.05);

  options.near_planar_ratio = 0;
  const SyntheticRig free_space = GenerateSyntheticRig(options);
  for (const RigImage& image : free_space.dataset.images) {
    for (const Correspondence& correspondence : image.correspondences) {
      EXPECT_GT(std::abs(correspondence.point3D.z()), 1e-9);
    }
  }
}

// The rig turns and tilts, so that rig poses are not all related by
// rotations about one axis.
TEST(SyntheticRig, TrajectoryRotatesAboutSeveralAxes) {
  for (const RigPreset preset : AllRigPresets()) {
    SCOPED_TRACE(RigPresetName(preset));
    SyntheticRigOptions options = SmallOptions(preset);
    options.num_framesets = 30;
    options.points_per_image = 0;
    const SyntheticRig rig = GenerateSyntheticRig(options);
    double max_yaw_change = 0, max_tilt_change = 0;
    const Eigen::Matrix3d first = rig.truth.rig_from_world[0].RotationMatrix();
    for (const Rigid3d& rig_from_world : rig.truth.rig_from_world) {
      const Eigen::Matrix3d rotation = rig_from_world.RotationMatrix();
      // World up seen from the rig: changes only with pitch and roll.
      const double tilt =
          std::acos(std::min(1.0, (rotation * Eigen::Vector3d::UnitZ())
                                      .dot(first * Eigen::Vector3d::UnitZ())));
      max_tilt_change = std::max(max_tilt_change, tilt * 180 / M_PI);
      max_yaw_change =
          std::max(max_yaw_change,
                   RotationDifferenceDeg(rig_from_world.rotation,
                                         rig.truth.rig_from_world[0].rotation));
    }
    EXPECT_GT(max_yaw_change, 20);
    EXPECT_GT(max_tilt_change, 1.5);
  }
}

TEST(SyntheticRig, SelectFramesetsKeepsTheChosenOnes) {
  const SyntheticRig rig =
      GenerateSyntheticRig(SmallOptions(RigPreset::kRing5));
  const SyntheticRig selected = SelectFramesets(rig, {9, 2, 5, 2, 40, -1});
  ASSERT_EQ(selected.dataset.frameset_names.size(), 3);
  EXPECT_EQ(selected.dataset.frameset_names[0], "000009");
  EXPECT_EQ(selected.dataset.frameset_names[1], "000002");
  EXPECT_EQ(selected.dataset.frameset_names[2], "000005");
  ASSERT_EQ(selected.truth.rig_from_world.size(), 3);
  EXPECT_EQ(selected.truth.rig_from_world[0].translation,
            rig.truth.rig_from_world[9].translation);
  EXPECT_EQ(selected.truth.cameras.size(), rig.truth.cameras.size());
  EXPECT_EQ(selected.dataset.cameras.size(), rig.dataset.cameras.size());
  ASSERT_EQ(selected.is_outlier.size(), selected.dataset.images.size());
  int expected_images = 0;
  for (const RigImage& image : rig.dataset.images) {
    expected_images += image.frameset_index == 9 || image.frameset_index == 2 ||
                       image.frameset_index == 5;
  }
  EXPECT_EQ(selected.dataset.images.size(), expected_images);
  for (size_t i = 0; i < selected.dataset.images.size(); ++i) {
    const RigImage& image = selected.dataset.images[i];
    EXPECT_EQ(image.name.substr(5, 6),
              selected.dataset.frameset_names[image.frameset_index]);
    // Still consistent with the truth after renumbering.
    for (size_t k = 0; k < image.correspondences.size(); ++k) {
      if (!selected.is_outlier[i][k]) {
        EXPECT_LT(
            TrueReprojectionError(selected, image, image.correspondences[k]),
            5.0);
      }
    }
  }
}

// image_height scales every preset camera to that many rows: width, focal
// lengths and principal point by the same factor, distortion unchanged (a
// pixel's ray is the same up to the factor), observations inside the larger
// images and exact; 0 and out-of-range values are refused or ignored.
TEST(SyntheticRig, ImageHeightScalesEveryCamera) {
  for (const RigPreset preset : AllRigPresets()) {
    SCOPED_TRACE(RigPresetName(preset));
    SyntheticRigOptions options = SmallOptions(preset);
    options.noise_px = 0;
    options.outlier_ratio = 0;
    const SyntheticRig original = GenerateSyntheticRig(options);
    options.image_height = 1080;
    const SyntheticRig scaled = GenerateSyntheticRig(options);
    ASSERT_EQ(scaled.truth.cameras.size(), original.truth.cameras.size());
    for (size_t c = 0; c < scaled.truth.cameras.size(); ++c) {
      const colmap::Camera& before = original.truth.cameras[c];
      const colmap::Camera& after = scaled.truth.cameras[c];
      const double factor = 1080.0 / before.Height();
      EXPECT_EQ(after.Height(), 1080u);
      EXPECT_EQ(after.Width(), std::round(factor * before.Width()));
      EXPECT_EQ(after.ModelId(), before.ModelId());
      EXPECT_NEAR(after.MeanFocalLength(),
                  factor * before.MeanFocalLength(), 1e-9 * factor * 1000);
      // The same ray through corresponding pixels (up to the rounding of
      // the width, below 1e-3 of a pixel's share).
      const Eigen::Vector2d pixel(0.3 * before.Width(), 0.7 * before.Height());
      EXPECT_LT((after.ImageToWorld(factor * pixel) -
                 before.ImageToWorld(pixel))
                    .norm(),
                2e-3);
      EXPECT_EQ(scaled.dataset.cameras[c].camera.Height(), 1080u);
    }
    double max_error = 0;
    for (const RigImage& image : scaled.dataset.images) {
      const colmap::Camera& camera = scaled.truth.cameras[image.camera_index];
      for (const Correspondence& correspondence : image.correspondences) {
        max_error = std::max(max_error, TrueReprojectionError(
                                            scaled, image, correspondence));
        EXPECT_GE(correspondence.point2D.y(), 0);
        EXPECT_LE(correspondence.point2D.y(), camera.Height());
        EXPECT_LE(correspondence.point2D.x(), camera.Width());
      }
    }
    EXPECT_LT(max_error, 1e-9);
  }
  SyntheticRigOptions options;
  std::string error;
  options.image_height = 8;
  EXPECT_FALSE(options.Check(&error));
  EXPECT_NE(error.find("image_height"), std::string::npos) << error;
}

TEST(SyntheticRig, InvalidOptionsGiveNoImages) {
  SyntheticRigOptions options;
  std::string error;
  EXPECT_TRUE(options.Check(&error));
  options.min_depth = 5;
  options.max_depth = 2;
  EXPECT_FALSE(options.Check(&error));
  EXPECT_NE(error.find("min_depth"), std::string::npos);
  EXPECT_TRUE(GenerateSyntheticRig(options).dataset.images.empty());
  options = SyntheticRigOptions();
  options.outlier_ratio = 1.5;
  EXPECT_FALSE(options.Check(&error));
  options = SyntheticRigOptions();
  options.num_framesets = 0;
  EXPECT_FALSE(options.Check(&error));
}

TEST(SyntheticRig, SetKnownIntrinsicsCopiesTheTruth) {
  SyntheticRig rig = GenerateSyntheticRig(SmallOptions(RigPreset::kStereoPair));
  SetKnownIntrinsics(&rig);
  for (size_t c = 0; c < rig.dataset.cameras.size(); ++c) {
    EXPECT_TRUE(rig.dataset.cameras[c].intrinsics_known);
    EXPECT_EQ(rig.dataset.cameras[c].camera.Params(),
              rig.truth.cameras[c].Params());
  }
}

// Each image's correspondences lie in one window of the requested size (up
// to the pixel noise), placed differently in different images.
TEST(SyntheticRig, FeatureWindowClustersEachImage) {
  SyntheticRigOptions options = SmallOptions(RigPreset::kRing5);
  options.feature_window = 0.3;
  options.noise_px = 0.5;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  ASSERT_FALSE(rig.dataset.images.empty());
  std::set<int> window_columns;
  for (const RigImage& image : rig.dataset.images) {
    ASSERT_GE(image.correspondences.size(), 50u) << image.name;
    Eigen::Vector2d low = image.correspondences[0].point2D, high = low;
    for (const Correspondence& correspondence : image.correspondences) {
      low = low.cwiseMin(correspondence.point2D);
      high = high.cwiseMax(correspondence.point2D);
    }
    // 0.3 * 640 = 192 px and 0.3 * 480 = 144 px, plus 4 sigma of noise.
    EXPECT_LE(high.x() - low.x(), 192 + 4) << image.name;
    EXPECT_LE(high.y() - low.y(), 144 + 4) << image.name;
    EXPECT_GE(high.x() - low.x(), 100) << image.name;
    window_columns.insert(static_cast<int>(low.x() / 100));
  }
  EXPECT_GE(window_columns.size(), 3u);
  options.feature_window = 0;
  std::string error;
  EXPECT_FALSE(options.Check(&error));
  EXPECT_NE(error.find("feature_window"), std::string::npos);
}

// ring_num_cameras: 5 reproduces ring5 exactly; 10 spaces the cameras 36
// degrees apart on the same 0.15 m ring with distinct focal lengths, and every
// image still gets its correspondences; other presets and sizes are refused.
TEST(SyntheticRig, RingWithNCameras) {
  SyntheticRigOptions options = SmallOptions(RigPreset::kRing5);
  const SyntheticRig ring5 = GenerateSyntheticRig(options);
  options.ring_num_cameras = 5;
  const SyntheticRig same = GenerateSyntheticRig(options);
  ASSERT_EQ(same.dataset.images.size(), ring5.dataset.images.size());
  for (size_t i = 0; i < ring5.dataset.images.size(); ++i) {
    ASSERT_EQ(same.dataset.images[i].correspondences.size(),
              ring5.dataset.images[i].correspondences.size());
    for (size_t k = 0; k < ring5.dataset.images[i].correspondences.size();
         ++k) {
      EXPECT_EQ(same.dataset.images[i].correspondences[k].point2D,
                ring5.dataset.images[i].correspondences[k].point2D);
    }
  }

  options.ring_num_cameras = 10;
  const SyntheticRig ring10 = GenerateSyntheticRig(options);
  ASSERT_EQ(ring10.truth.cameras.size(), 10u);
  ASSERT_EQ(ring10.dataset.cameras.size(), 10u);
  std::set<double> focal_lengths;
  for (int i = 0; i < 10; ++i) {
    const colmap::Camera& camera = ring10.truth.cameras[i];
    EXPECT_EQ(camera.ModelName(), "OPENCV");
    EXPECT_EQ(ring10.truth.camera_names[i], "cam" + std::to_string(i));
    EXPECT_NEAR(camera.FocalLengthX(),
                ring5.truth.cameras[i % 5].FocalLengthX() * (i < 5 ? 1 : 1.03),
                1e-9);
    focal_lengths.insert(camera.FocalLengthX());
    // Neighbours 36 degrees apart (up to the few degrees of pitch and
    // roll), centers 2 r sin(pi i / 10) from the reference camera's.
    const double angle =
        RotationDifferenceDeg(ring10.truth.cam_from_rig[0].rotation,
                              ring10.truth.cam_from_rig[i].rotation);
    EXPECT_NEAR(angle, std::min(36.0 * i, 360 - 36.0 * i), 6.0) << i;
    EXPECT_NEAR(ring10.truth.cam_from_rig[i].Center().norm(),
                2 * 0.15 * std::sin(M_PI * i / 10), 0.02)
        << i;
  }
  EXPECT_EQ(focal_lengths.size(), 10u);
  std::vector<int> images_per_camera(10, 0);
  for (const RigImage& image : ring10.dataset.images) {
    ++images_per_camera[image.camera_index];
    EXPECT_EQ(image.correspondences.size(), 100u) << image.name;
  }
  for (int i = 0; i < 10; ++i) EXPECT_GE(images_per_camera[i], 8) << i;

  std::string error;
  EXPECT_TRUE(options.Check(&error)) << error;
  options.ring_num_cameras = 1;
  EXPECT_FALSE(options.Check(&error));
  EXPECT_NE(error.find("ring_num_cameras"), std::string::npos);
  options.ring_num_cameras = 10;
  options.preset = RigPreset::kFisheyeHelmet5;
  EXPECT_FALSE(options.Check(&error));
}

}  // namespace synthetic_rig_test
}  // namespace rig_calibrator

namespace rig_calibrator {
namespace synthetic_rig_test {

// Degenerate rigs (issue 15): several stereo pairs, facing one way or
// alternately forward and backward.
TEST(SyntheticRig, StereoPairsFaceForwardOrAlternately) {
  SyntheticRigOptions options = SmallOptions(RigPreset::kStereoPair);
  options.stereo_num_pairs = 2;
  for (const bool alternate : {false, true}) {
    options.stereo_alternate_facing = alternate;
    const SyntheticRig rig = GenerateSyntheticRig(options);
    ASSERT_EQ(rig.truth.cameras.size(), 4u);
    for (int c = 1; c < 4; ++c) {
      const double angle = RotationDifferenceDeg(
          Eigen::Quaterniond::Identity(), rig.truth.cam_from_rig[c].rotation);
      EXPECT_NEAR(angle, alternate && c >= 2 ? 180 : 0, 0.5) << c;
    }
    // The second pair 0.25 m above the first (camera y points down), 0.3 m
    // behind when it faces backward.
    const Eigen::Vector3d center = rig.truth.cam_from_rig[2].Center();
    EXPECT_NEAR(center.y(), -0.25, 1e-9);
    EXPECT_NEAR(center.z(), alternate ? -0.3 : 0, 1e-9);
    std::string error;
    EXPECT_TRUE(options.Check(&error)) << error;
  }
  options.preset = RigPreset::kRing5;
  std::string error;
  EXPECT_FALSE(options.Check(&error));
  EXPECT_NE(error.find("need the stereo_pair preset"), std::string::npos);
}

// rotation_only keeps the body (ring center) at one point; map_scale scales
// every 3D point and translation and leaves the pixels bit for bit.
TEST(SyntheticRig, RotationOnlyAndMapScale) {
  SyntheticRigOptions options = SmallOptions(RigPreset::kRing5);
  options.rotation_only = true;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  // Camera 0 is 0.15 m from the fixed ring center, so the rig origin moves
  // on a sphere of that radius.
  const Eigen::Vector3d center0 =
      rig.truth.rig_from_world[0].Inverse().translation;
  for (const Rigid3d& rig_from_world : rig.truth.rig_from_world) {
    EXPECT_LT((rig_from_world.Inverse().translation - center0).norm(),
              0.3 + 1e-9);
  }
  options.map_scale = 1000;
  const SyntheticRig scaled = GenerateSyntheticRig(options);
  ASSERT_EQ(scaled.dataset.images.size(), rig.dataset.images.size());
  for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
    const auto& a = rig.dataset.images[i].correspondences;
    const auto& b = scaled.dataset.images[i].correspondences;
    ASSERT_EQ(a.size(), b.size());
    for (size_t k = 0; k < a.size(); ++k) {
      EXPECT_EQ(a[k].point2D, b[k].point2D);
      EXPECT_EQ(1000 * a[k].point3D, b[k].point3D);
    }
  }
  for (size_t c = 0; c < rig.truth.cam_from_rig.size(); ++c) {
    EXPECT_EQ(1000 * rig.truth.cam_from_rig[c].translation,
              scaled.truth.cam_from_rig[c].translation);
  }
  options.map_scale = 0;
  std::string error;
  EXPECT_FALSE(options.Check(&error));
}

// map_observations_per_image keeps at most that many of each map image's
// visible points, the points the rig observes correctly first, and leaves
// the rig's correspondences as they are.
TEST(SyntheticRig, MapObservationsPerImageCapsEachMapImage) {
  SyntheticRigOptions options;
  options.num_framesets = 12;
  options.points_per_image = 80;
  options.num_map_images = 6;
  const SyntheticRig all = GenerateSyntheticRig(options);
  options.map_observations_per_image = 100;
  const SyntheticRig capped = GenerateSyntheticRig(options);
  ASSERT_EQ(capped.dataset.map_images.size(), 6u);
  ASSERT_EQ(all.dataset.map_images.size(), 6u);
  ASSERT_EQ(capped.dataset.images.size(), all.dataset.images.size());
  for (size_t i = 0; i < all.dataset.images.size(); ++i) {
    EXPECT_EQ(capped.dataset.images[i].correspondences.size(),
              all.dataset.images[i].correspondences.size());
  }
  std::set<int64_t> rig_points;
  for (size_t i = 0; i < capped.dataset.images.size(); ++i) {
    const auto& correspondences = capped.dataset.images[i].correspondences;
    for (size_t k = 0; k < correspondences.size(); ++k) {
      if (!capped.is_outlier[i][k]) {
        rig_points.insert(correspondences[k].point3D_id);
      }
    }
  }
  for (size_t m = 0; m < 6; ++m) {
    const auto& kept = capped.dataset.map_images[m].observations;
    EXPECT_EQ(kept.size(), 100u) << m;
    for (size_t k = 0; k < kept.size(); ++k) {
      EXPECT_EQ(kept[k].point2D_idx, k);
    }
  }
  // The first map image is at the same pose in both (the later ones are
  // not: their poses are drawn after the pixel noise of the observations
  // before them), so its visible points are those of the uncapped one.
  {
    const auto& kept = capped.dataset.map_images[0].observations;
    const auto& visible = all.dataset.map_images[0].observations;
    ASSERT_GT(visible.size(), 100u);
    std::set<int64_t> visible_ids;
    int visible_rig_points = 0;
    for (const MapObservation& observation : visible) {
      visible_ids.insert(observation.point3D_id);
      visible_rig_points += rig_points.count(observation.point3D_id);
    }
    int kept_rig_points = 0;
    for (const MapObservation& observation : kept) {
      EXPECT_EQ(visible_ids.count(observation.point3D_id), 1u);
      kept_rig_points += rig_points.count(observation.point3D_id);
    }
    EXPECT_EQ(kept_rig_points, std::min(100, visible_rig_points));
  }
  options.map_observations_per_image = -1;
  std::string error;
  EXPECT_FALSE(options.Check(&error));
  EXPECT_NE(error.find("map_observations_per_image"), std::string::npos);
}

}  // namespace synthetic_rig_test
}  // namespace rig_calibrator
