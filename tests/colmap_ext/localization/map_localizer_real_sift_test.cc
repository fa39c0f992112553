// The map localizer on real SIFT features (COLMAP's CPU extractor) of
// rendered views of a textured plane.
#include <colmap/base/database.h>
#include <colmap/feature/sift.h>
#include <colmap/util/bitmap.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "colmap_ext/localization/map_localizer.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace map_localizer_real_sift_test {

// A grey texture on the world plane z = 0 (x, y in [-1.5, 1.5]): random
// Gaussian blobs of several sizes, which SIFT detects at several scales.
class PlaneTexture {
 public:
  explicit PlaneTexture(const unsigned seed) : values_(kSize * kSize, 128) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> position(0, kSize);
    std::uniform_real_distribution<float> sigma(1.5f, 10.0f);
    std::uniform_real_distribution<float> amplitude(40, 120);
    std::bernoulli_distribution sign(0.5);
    for (int blob = 0; blob < 2500; ++blob) {
      const float cx = position(random);
      const float cy = position(random);
      const float s = sigma(random);
      const float a = sign(random) ? amplitude(random) : -amplitude(random);
      const int radius = static_cast<int>(std::ceil(3 * s));
      for (int y = std::max(0, static_cast<int>(cy) - radius);
           y < std::min(kSize, static_cast<int>(cy) + radius + 1); ++y) {
        for (int x = std::max(0, static_cast<int>(cx) - radius);
             x < std::min(kSize, static_cast<int>(cx) + radius + 1); ++x) {
          const float d2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
          values_[y * kSize + x] += a * std::exp(-d2 / (2 * s * s));
        }
      }
    }
  }

  // Bilinear sample at world (x, y); mid grey outside the texture.
  float Sample(const double x, const double y) const {
    const double u = (x + 1.5) / 3.0 * kSize - 0.5;
    const double v = (y + 1.5) / 3.0 * kSize - 0.5;
    if (u < 0 || v < 0 || u >= kSize - 1 || v >= kSize - 1) return 128;
    const int u0 = static_cast<int>(u);
    const int v0 = static_cast<int>(v);
    const float fu = static_cast<float>(u - u0);
    const float fv = static_cast<float>(v - v0);
    const auto at = [this](int uu, int vv) { return values_[vv * kSize + uu]; };
    return (1 - fv) * ((1 - fu) * at(u0, v0) + fu * at(u0 + 1, v0)) +
           fv * ((1 - fu) * at(u0, v0 + 1) + fu * at(u0 + 1, v0 + 1));
  }

 private:
  static constexpr int kSize = 1024;
  std::vector<float> values_;
};

// Intersection of the ray of `pixel` with the plane z = 0.
Eigen::Vector3d BackProjectToPlane(const colmap::Camera& camera,
                                   const Rigid3d& cam_from_world,
                                   const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d normalized = camera.ImageToWorld(pixel);
  const Eigen::Vector3d direction =
      cam_from_world.RotationMatrix().transpose() *
      Eigen::Vector3d(normalized.x(), normalized.y(), 1);
  const Eigen::Vector3d center = cam_from_world.Center();
  return center - center.z() / direction.z() * direction;
}

colmap::Bitmap RenderView(const PlaneTexture& texture,
                          const colmap::Camera& camera,
                          const Rigid3d& cam_from_world) {
  colmap::Bitmap bitmap;
  bitmap.Allocate(camera.Width(), camera.Height(), /*as_rgb=*/false);
  for (size_t row = 0; row < camera.Height(); ++row) {
    for (size_t col = 0; col < camera.Width(); ++col) {
      // COLMAP pixel centers are at +0.5.
      const Eigen::Vector3d point = BackProjectToPlane(
          camera, cam_from_world, Eigen::Vector2d(col + 0.5, row + 0.5));
      const float value =
          std::clamp(texture.Sample(point.x(), point.y()), 0.0f, 255.0f);
      bitmap.SetPixel(col, row,
                      colmap::BitmapColor<uint8_t>(
                          static_cast<uint8_t>(std::lround(value))));
    }
  }
  return bitmap;
}

Rigid3d LookingAtPlane(const Eigen::Vector3d& center, const double yaw_deg,
                       const double roll_deg) {
  const Eigen::Matrix3d rotation =
      (Eigen::AngleAxisd(roll_deg * M_PI / 180, Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  return Rigid3d(rotation, -rotation * center);
}

// Real SIFT (COLMAP's CPU extractor) on two rendered views of a textured
// plane: the map is view A with one 3D point per keypoint (back-projected
// onto the plane), the rig image is view B; a correspondence is correct if
// its map point projects within 2 px of its keypoint in view B.
TEST(MapLocalizerRealSiftTest, LocalizesARenderedViewOfATexturedPlane) {
  const PlaneTexture texture(21);
  colmap::Camera camera;
  camera.InitializeWithName("PINHOLE", 500, 640, 480);
  camera.SetCameraId(1);
  const Rigid3d map_from_world =
      LookingAtPlane(Eigen::Vector3d(0, 0, -2), 0, 0);
  const Rigid3d rig_from_world =
      LookingAtPlane(Eigen::Vector3d(-0.3, 0.1, -1.8), 12, 8);

  colmap::SiftExtractionOptions extraction;
  extraction.use_gpu = false;
  extraction.num_threads = 1;
  colmap::FeatureKeypoints map_keypoints;
  colmap::FeatureKeypoints rig_keypoints;
  colmap::FeatureDescriptors map_descriptors;
  colmap::FeatureDescriptors rig_descriptors;
  ASSERT_TRUE(colmap::ExtractSiftFeaturesCPU(
      extraction, RenderView(texture, camera, map_from_world), &map_keypoints,
      &map_descriptors));
  ASSERT_TRUE(colmap::ExtractSiftFeaturesCPU(
      extraction, RenderView(texture, camera, rig_from_world), &rig_keypoints,
      &rig_descriptors));
  ASSERT_GT(map_keypoints.size(), 300u);
  ASSERT_GT(rig_keypoints.size(), 300u);

  testing::ScopedTempDir temp_dir;
  const std::string database_path = temp_dir.File("plane.db");
  colmap::Reconstruction map;
  {
    colmap::Database database(database_path);
    database.WriteCamera(camera, /*use_camera_id=*/true);
    colmap::Image image;
    image.SetName("map/a.png");
    image.SetCameraId(camera.CameraId());
    image.SetImageId(database.WriteImage(image));
    database.WriteKeypoints(image.ImageId(), map_keypoints);
    database.WriteDescriptors(image.ImageId(), map_descriptors);
    std::vector<Eigen::Vector2d> points2D;
    for (const colmap::FeatureKeypoint& keypoint : map_keypoints) {
      points2D.emplace_back(keypoint.x, keypoint.y);
    }
    image.SetPoints2D(points2D);
    image.SetQvec(map_from_world.Qvec());
    image.SetTvec(map_from_world.translation);
    map.AddCamera(camera);
    map.AddImage(image);
    map.RegisterImage(image.ImageId());
    for (colmap::point2D_t idx = 0; idx < points2D.size(); ++idx) {
      colmap::Track track;
      track.AddElement(image.ImageId(), idx);
      map.AddPoint3D(BackProjectToPlane(camera, map_from_world, points2D[idx]),
                     track);
    }
    colmap::Image rig_image;
    rig_image.SetName("cam0/0001.png");
    rig_image.SetCameraId(camera.CameraId());
    const colmap::image_t rig_image_id = database.WriteImage(rig_image);
    database.WriteKeypoints(rig_image_id, rig_keypoints);
    database.WriteDescriptors(rig_image_id, rig_descriptors);
  }
  DatabaseReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(database_path, &error)) << error;

  for (const LocalizationMode mode :
       {LocalizationMode::kDirect, LocalizationMode::kRetrieval}) {
    MapLocalizerOptions options;
    options.mode = mode;
    std::unique_ptr<MapLocalizer> localizer =
        MapLocalizer::Create(options, map, &reader, &error);
    ASSERT_NE(localizer, nullptr) << error;
    ImageLocalization result;
    ASSERT_TRUE(localizer->Localize("cam0/0001.png", &result, &error)) << error;
    int num_correct = 0;
    for (const Correspondence& correspondence : result.correspondences) {
      const Eigen::Vector3d in_camera = rig_from_world * correspondence.point3D;
      const Eigen::Vector2d projection =
          camera.WorldToImage(in_camera.hnormalized());
      num_correct += (projection - correspondence.point2D).norm() < 2.0;
    }
    const int num_found = static_cast<int>(result.correspondences.size());
    std::cout << LocalizationModeName(mode) << ": " << map_keypoints.size()
              << " map / " << rig_keypoints.size() << " rig SIFT features, "
              << num_found << " correspondences, " << num_correct
              << " within 2 px" << std::endl;
    EXPECT_GT(num_found, 100);
    EXPECT_GE(num_correct, 0.95 * num_found);
  }
}

}  // namespace map_localizer_real_sift_test
}  // namespace rig_calibrator
