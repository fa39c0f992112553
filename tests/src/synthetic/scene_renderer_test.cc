#include "src/synthetic/scene_renderer.h"

#include <colmap/feature/sift.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <optional>
#include <random>

#include "src/synthetic/capture_model.h"
#include "src/synthetic/rendered_dataset.h"
#include "src/synthetic/rig_trajectory.h"
#include "src/synthetic/synthetic_rig.h"
#include "src/synthetic/textured_scene.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace scene_renderer_test {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
      .count();
}

using testing::MakeCamera;

// cam_from_world of a camera at `center` looking along world +x, image x
// along world -y, image y along world -z, then turned by `yaw` about z.
Rigid3d LookingAlongX(const Eigen::Vector3d& center, double yaw = 0) {
  Eigen::Matrix3d world_from_cam;
  world_from_cam.col(0) = -Eigen::Vector3d::UnitY();
  world_from_cam.col(1) = -Eigen::Vector3d::UnitZ();
  world_from_cam.col(2) = Eigen::Vector3d::UnitX();
  world_from_cam =
      Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
      world_from_cam;
  return Rigid3d(world_from_cam, center).Inverse();
}

RenderOptions GreyNoiseless() {
  RenderOptions options;
  options.as_rgb = false;
  options.noise_stddev = 0;
  return options;
}

// The grey levels of a bitmap, row-major.
std::vector<double> GreyLevels(const colmap::Bitmap& bitmap) {
  std::vector<double> levels;
  for (int y = 0; y < bitmap.Height(); ++y) {
    for (int x = 0; x < bitmap.Width(); ++x) {
      colmap::BitmapColor<uint8_t> color;
      bitmap.GetPixel(x, y, &color);
      levels.push_back(color.r);
    }
  }
  return levels;
}

// Bilinear interpolation at a point in COLMAP pixel coordinates (pixel
// (x, y) has its center at (x + 0.5, y + 0.5)).
double Sample(const std::vector<double>& levels, int width,
              const Eigen::Vector2d& point) {
  const double x = point.x() - 0.5;
  const double y = point.y() - 0.5;
  const int x0 = static_cast<int>(std::floor(x));
  const int y0 = static_cast<int>(std::floor(y));
  const double fx = x - x0;
  const double fy = y - y0;
  auto at = [&](int u, int v) { return levels[v * width + u]; };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
         fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

double NormalizedCrossCorrelation(const std::vector<double>& a,
                                  const std::vector<double>& b) {
  double mean_a = 0, mean_b = 0;
  for (size_t k = 0; k < a.size(); ++k) {
    mean_a += a[k];
    mean_b += b[k];
  }
  mean_a /= a.size();
  mean_b /= b.size();
  double ab = 0, aa = 0, bb = 0;
  for (size_t k = 0; k < a.size(); ++k) {
    ab += (a[k] - mean_a) * (b[k] - mean_b);
    aa += (a[k] - mean_a) * (a[k] - mean_a);
    bb += (b[k] - mean_b) * (b[k] - mean_b);
  }
  return ab / std::sqrt(aa * bb);
}

TEST(TexturedScene, RaysHitTheRightFaces) {
  const TexturedScene room = TexturedScene::Make(SceneType::kRoom, 0);
  SceneHit hit;
  // Up to the ceiling of the enclosure, seen from inside.
  ASSERT_TRUE(room.Intersect(Eigen::Vector3d(1, 1, 1.5),
                             Eigen::Vector3d::UnitZ(), &hit));
  EXPECT_NEAR(hit.distance, 1.5, 1e-12);
  EXPECT_NEAR((hit.normal - Eigen::Vector3d(0, 0, -1)).norm(), 0, 1e-12);
  // Along +y into the pillar's -y face.
  ASSERT_TRUE(room.Intersect(Eigen::Vector3d(0, -1.5, 1.5),
                             Eigen::Vector3d::UnitY(), &hit));
  EXPECT_NEAR(hit.distance, 1.25, 1e-12);
  EXPECT_NEAR((hit.point - Eigen::Vector3d(0, -0.25, 1.5)).norm(), 0, 1e-12);
  EXPECT_NEAR((hit.normal - Eigen::Vector3d(0, -1, 0)).norm(), 0, 1e-12);
  EXPECT_EQ(hit.face, 1 * 6 + 1 * 2 + 0);
  // Outdoors, straight up is the sky.
  const TexturedScene street = TexturedScene::Make(SceneType::kStreet, 0);
  EXPECT_FALSE(street.Intersect(Eigen::Vector3d(0, 0, 1.6),
                                Eigen::Vector3d::UnitZ(), &hit));
  EXPECT_TRUE(room.IsFree(Eigen::Vector3d(1, 1, 1.5), 0.3));
  EXPECT_FALSE(room.IsFree(Eigen::Vector3d(0, 0.4, 1.5), 0.3));  // pillar
  EXPECT_FALSE(room.IsFree(Eigen::Vector3d(3.9, 0, 1.5), 0.3));  // wall
}

TEST(TexturedScene, TextureIsFixedInTheSceneAndFilteredByFootprint) {
  const TexturedScene scene = TexturedScene::Make(SceneType::kRoom, 5);
  SceneHit hit;
  ASSERT_TRUE(scene.Intersect(Eigen::Vector3d(1, 1, 1.5),
                              Eigen::Vector3d::UnitZ(), &hit));
  // The same point reached from elsewhere has the same texture.
  SceneHit other;
  const Eigen::Vector3d origin(0.2, 1.8, 0.5);
  ASSERT_TRUE(
      scene.Intersect(origin, (hit.point - origin).normalized(), &other));
  EXPECT_NEAR((other.point - hit.point).norm(), 0, 1e-9);
  EXPECT_EQ(scene.Radiance(hit, 0.002), scene.Radiance(other, 0.002));
  // Fine detail: neighbouring points 1 cm apart differ; with a 1 m footprint
  // only the coarse octaves remain, so the texture varies much less.
  double fine_variation = 0, coarse_variation = 0;
  for (int k = 0; k < 200; ++k) {
    SceneHit a = hit, b = hit;
    a.point.x() = -3 + 0.03 * k;
    b.point.x() = a.point.x() + 0.01;
    fine_variation +=
        std::abs(scene.Radiance(a, 0.002) - scene.Radiance(b, 0.002));
    coarse_variation +=
        std::abs(scene.Radiance(a, 1.0) - scene.Radiance(b, 1.0));
  }
  EXPECT_GT(fine_variation / 200, 0.02);
  EXPECT_LT(coarse_variation, 0.2 * fine_variation);
  // A different seed gives a different texture.
  const TexturedScene reseeded = TexturedScene::Make(SceneType::kRoom, 6);
  EXPECT_NE(scene.Radiance(hit, 0.002), reseeded.Radiance(hit, 0.002));
}

TEST(SceneRenderer, RenderingIsDeterministic) {
  const TexturedScene scene = TexturedScene::Make(SceneType::kRoom, 1);
  const colmap::Camera camera =
      MakeCamera("OPENCV", 160, 120, {110, 112, 81, 59, -0.2, 0.05, 0, 0});
  const Rigid3d cam_from_world = LookingAlongX(Eigen::Vector3d(1, -1, 1.5));
  RenderOptions options;  // RGB with noise
  const colmap::Bitmap first =
      RenderImage(scene, camera, cam_from_world, options, 42);
  const colmap::Bitmap second =
      RenderImage(scene, camera, cam_from_world, options, 42);
  ASSERT_EQ(first.Width(), 160);
  ASSERT_EQ(first.Height(), 120);
  ASSERT_TRUE(first.IsRGB());
  EXPECT_EQ(first.ConvertToRowMajorArray(), second.ConvertToRowMajorArray());
  const colmap::Bitmap other_noise =
      RenderImage(scene, camera, cam_from_world, options, 43);
  EXPECT_NE(first.ConvertToRowMajorArray(),
            other_noise.ConvertToRowMajorArray());
  options.supersampling = 0;
  EXPECT_EQ(RenderImage(scene, camera, cam_from_world, options, 42).Width(), 0);
}

// A point of the scene appears where COLMAP's camera model projects it: the
// patch around the point's projection in a pinhole view matches, after the
// local affine map between the views, the patch around its projection in a
// strongly distorted view, at a shift below a quarter pixel.
TEST(SceneRenderer, ScenePointsAppearWhereTheCameraModelProjectsThem) {
  const TexturedScene scene = TexturedScene::Make(SceneType::kRoom, 3);
  const Eigen::Vector3d point(3.9, -0.3, 1.5);  // on the east wall panel
  const colmap::Camera pinhole =
      MakeCamera("PINHOLE", 320, 240, {250, 250, 160, 120});
  const Rigid3d pinhole_from_world =
      LookingAlongX(Eigen::Vector3d(1.5, -0.3, 1.5));
  const colmap::Camera distorted = MakeCamera(
      "OPENCV", 640, 480, {420, 415, 330, 236, -0.3, 0.08, 0.001, -0.0005});
  const Rigid3d distorted_from_world =
      LookingAlongX(Eigen::Vector3d(1.5, 1.0, 1.8), 0.05);
  auto project = [&](const colmap::Camera& camera, const Rigid3d& pose,
                     const Eigen::Vector3d& world) {
    return camera.WorldToImage((pose * world).hnormalized());
  };
  const Eigen::Vector2d in_pinhole =
      project(pinhole, pinhole_from_world, point);
  const Eigen::Vector2d in_distorted =
      project(distorted, distorted_from_world, point);
  // Far from the distorted camera's center, where distortion moves points by
  // many pixels.
  ASSERT_GT((in_distorted - Eigen::Vector2d(330, 236)).norm(), 180);
  const Eigen::Vector2d undistorted =
      Eigen::Vector2d(420, 415).cwiseProduct(
          distorted.ImageToWorld(in_distorted)) +
      Eigen::Vector2d(330, 236);
  ASSERT_GT((undistorted - in_distorted).norm(), 10);

  // The local affine map from pinhole to distorted pixels, through the wall
  // plane x = 3.9: pinhole pixel -> ray -> wall point -> distorted pixel.
  auto to_distorted = [&](const Eigen::Vector2d& pinhole_pixel) {
    const Eigen::Vector3d ray_in_world =
        pinhole_from_world.rotation.conjugate() *
        pinhole.ImageToWorld(pinhole_pixel).homogeneous();
    const Eigen::Vector3d center = pinhole_from_world.Center();
    const double t = (point.x() - center.x()) / ray_in_world.x();
    return project(distorted, distorted_from_world, center + t * ray_in_world);
  };

  const colmap::Bitmap pinhole_image =
      RenderImage(scene, pinhole, pinhole_from_world, GreyNoiseless(), 0);
  const colmap::Bitmap distorted_image =
      RenderImage(scene, distorted, distorted_from_world, GreyNoiseless(), 0);
  const std::vector<double> pinhole_levels = GreyLevels(pinhole_image);
  const std::vector<double> distorted_levels = GreyLevels(distorted_image);

  constexpr int kRadius = 12;
  std::vector<double> reference;
  std::vector<Eigen::Vector2d> mapped;
  for (int dy = -kRadius; dy <= kRadius; ++dy) {
    for (int dx = -kRadius; dx <= kRadius; ++dx) {
      const Eigen::Vector2d pixel = in_pinhole + Eigen::Vector2d(dx, dy);
      reference.push_back(Sample(pinhole_levels, 320, pixel));
      mapped.push_back(to_distorted(pixel));
    }
  }
  double best_score = -2;
  Eigen::Vector2d best_shift = Eigen::Vector2d::Zero();
  for (double sy = -2; sy <= 2; sy += 0.125) {
    for (double sx = -2; sx <= 2; sx += 0.125) {
      std::vector<double> candidate;
      for (const Eigen::Vector2d& p : mapped) {
        candidate.push_back(
            Sample(distorted_levels, 640, p + Eigen::Vector2d(sx, sy)));
      }
      const double score = NormalizedCrossCorrelation(reference, candidate);
      if (score > best_score) {
        best_score = score;
        best_shift = Eigen::Vector2d(sx, sy);
      }
    }
  }
  std::cout << "patch match: NCC " << best_score << " at a shift of "
            << best_shift.transpose() << " px" << std::endl;
  EXPECT_GT(best_score, 0.85);
  EXPECT_LE(best_shift.norm(), 0.25) << best_shift.transpose();
}

TEST(SceneRenderer, FisheyeRaysAreFiniteAndBeyondNinetyDegreesAreBlack) {
  const TexturedScene scene = TexturedScene::Make(SceneType::kRoom, 2);
  const Rigid3d cam_from_world = LookingAlongX(Eigen::Vector3d(0, -1.5, 1.5));
  // The helmet preset's fisheye (about 150 degrees diagonally): every pixel
  // has a ray.
  const colmap::Camera helmet =
      MakeRigPreset(RigPreset::kFisheyeHelmet5).cameras[0];
  const CameraRays helmet_rays(helmet, 1);
  EXPECT_EQ(helmet_rays.NumMaskedPixels(), 0);
  // A fisheye whose corners are 150 degrees off axis: the corners have no
  // ray (COLMAP 3.8's model cannot represent them) and must be black, and
  // the rest must be finite, unit rays.
  const colmap::Camera wide =
      MakeCamera("OPENCV_FISHEYE", 200, 150, {48, 48, 100, 75, 0, 0, 0, 0});
  const CameraRays wide_rays(wide, 2);
  EXPECT_GT(wide_rays.NumMaskedPixels(), 100);
  EXPECT_LT(wide_rays.NumMaskedPixels(), 200 * 150 / 2);
  int num_valid = 0;
  for (int y = 0; y < 150; ++y) {
    for (int x = 0; x < 200; ++x) {
      ASSERT_TRUE(std::isfinite(wide_rays.PixelAngle(x, y)));
      for (int s = 0; s < wide_rays.NumSamples(); ++s) {
        const Eigen::Vector3f& ray = wide_rays.Ray(x, y, s);
        ASSERT_TRUE(ray.allFinite());
        if (!ray.isZero()) {
          EXPECT_NEAR(ray.norm(), 1, 1e-6);
          EXPECT_GT(ray.z(), 0);
          ++num_valid;
        }
      }
    }
  }
  EXPECT_GT(num_valid, 200 * 150 * 4 / 2);
  const colmap::Bitmap image =
      RenderImage(scene, wide, cam_from_world, GreyNoiseless(), 0);
  colmap::BitmapColor<uint8_t> corner, center;
  ASSERT_TRUE(image.GetPixel(0, 0, &corner));
  ASSERT_TRUE(image.GetPixel(100, 75, &center));
  EXPECT_EQ(corner.r, 0);
  EXPECT_GT(center.r, 0);
}

// The real component: COLMAP's CPU SIFT finds over 1000 features in a
// rendered 640 x 480 image of every scene (a map view of each).
TEST(SceneRenderer, SiftFindsThousandsOfFeatures) {
  colmap::SiftExtractionOptions sift_options;
  sift_options.use_gpu = false;
  sift_options.num_threads = 1;
  for (const SceneType type : AllSceneTypes()) {
    RenderedDatasetOptions options;
    options.scene = type;
    options.num_map_images = 8;
    options.num_framesets = 1;
    RenderedDatasetPlan plan;
    std::string error;
    ASSERT_TRUE(PlanRenderedDataset(options, &plan, &error)) << error;
    auto start = std::chrono::steady_clock::now();
    const colmap::Bitmap image =
        RenderImage(plan.scene, plan.map_camera, plan.map_cam_from_world[1],
                    RenderOptions(), 0);
    const double render_seconds = SecondsSince(start);
    start = std::chrono::steady_clock::now();
    colmap::FeatureKeypoints keypoints;
    colmap::FeatureDescriptors descriptors;
    ASSERT_TRUE(colmap::ExtractSiftFeaturesCPU(
        sift_options, image.CloneAsGrey(), &keypoints, &descriptors));
    std::cout << SceneTypeName(type) << ": rendered 640x480 in "
              << render_seconds << " s, " << keypoints.size()
              << " SIFT features in " << SecondsSince(start) << " s"
              << std::endl;
    EXPECT_GT(keypoints.size(), 1000u) << SceneTypeName(type);
  }
}

// The position of the patch of `reference` (levels, row-major, width
// `reference_width`) of radius kPatchRadius around `reference_point` in
// `image` (width `image_width`): the best normalized cross-correlation
// within `search_radius` px of `start`, on a 1 px grid, then refined on a
// 1/16 px grid within 1 px.
constexpr int kPatchRadius = 10;
Eigen::Vector2d FindPatch(const std::vector<double>& reference,
                          int reference_width,
                          const Eigen::Vector2d& reference_point,
                          const std::vector<double>& image, int image_width,
                          const Eigen::Vector2d& start, double search_radius,
                          double* best_score) {
  std::vector<double> patch;
  for (int dy = -kPatchRadius; dy <= kPatchRadius; ++dy) {
    for (int dx = -kPatchRadius; dx <= kPatchRadius; ++dx) {
      patch.push_back(Sample(reference, reference_width,
                             reference_point + Eigen::Vector2d(dx, dy)));
    }
  }
  auto score_at = [&](const Eigen::Vector2d& point) {
    std::vector<double> candidate;
    for (int dy = -kPatchRadius; dy <= kPatchRadius; ++dy) {
      for (int dx = -kPatchRadius; dx <= kPatchRadius; ++dx) {
        candidate.push_back(
            Sample(image, image_width, point + Eigen::Vector2d(dx, dy)));
      }
    }
    return NormalizedCrossCorrelation(patch, candidate);
  };
  *best_score = -2;
  Eigen::Vector2d best = start;
  auto search = [&](const Eigen::Vector2d& center, double radius,
                    double step) {
    for (double sy = -radius; sy <= radius; sy += step) {
      for (double sx = -radius; sx <= radius; sx += step) {
        const Eigen::Vector2d point = center + Eigen::Vector2d(sx, sy);
        const double score = score_at(point);
        if (score > *best_score) {
          *best_score = score;
          best = point;
        }
      }
    }
  };
  search(start, std::ceil(search_radius), 1.0);
  search(best, 1.0, 1.0 / 16);
  return best;
}

// A capture of a forward-looking PINHOLE camera on the synthetic trajectory,
// placed so that at `time_s` the camera stands at `center` looking along
// world +x, at the time of the trajectory's fastest turn in its first 10 s.
struct MovingCamera {
  colmap::Camera camera =
      MakeCamera("PINHOLE", 320, 240, {250, 250, 160, 120});
  std::optional<RigTrajectory> trajectory;
  ImageCapture capture;

  MovingCamera(const Eigen::Vector3d& center, double speed_m_s,
               double turn_rate_deg_s) {
    std::mt19937 rng(7);
    trajectory.emplace(MotionProfile(), speed_m_s, turn_rate_deg_s,
                       /*rotation_only=*/false, &rng);
    double time_s = 0;
    for (double t = 0; t < 10; t += 0.01) {
      if (trajectory->AngularVelocity(t).norm() >
          trajectory->AngularVelocity(time_s).norm()) {
        time_s = t;
      }
    }
    capture.trajectory = &*trajectory;
    // The camera is the rig; the body looks along its x axis.
    capture.body_from_rig = LookingAlongX(Eigen::Vector3d::Zero()).Inverse();
    capture.world_from_trajectory =
        Rigid3d(Eigen::Matrix3d::Identity(), center) *
        trajectory->WorldFromBody(time_s).Inverse();
    capture.top_row_time_s = time_s;
  }
};

// A rolling-shutter image shows each scene point where the rolling-shutter
// projection puts it: the point seen at pixel (200.5, 180.5) by the pose of
// row 180 is found there (patch of a global-shutter image at that row's
// time), sub-pixel, while in a global-shutter image at the top row's time it
// is where that pose projects it, several pixels away.
TEST(SceneRenderer, RollingShutterShowsPointsAtTheirRollingShutterProjection) {
  const TexturedScene scene = TexturedScene::Make(SceneType::kRoom, 3);
  MovingCamera moving(Eigen::Vector3d(1.5, -0.3, 1.5), 1.5, 120);
  ImageCapture& capture = moving.capture;
  capture.line_delay_s = 100e-6;  // 24 ms readout of 240 rows
  const colmap::Camera& camera = moving.camera;
  const CameraRays rays(camera, 2);

  const Eigen::Vector2d pixel(200.5, 180.5);
  const Rigid3d row_pose = capture.CamFromWorldAt(capture.RowTime(pixel.y()));
  SceneHit hit;
  ASSERT_TRUE(scene.Intersect(
      row_pose.Center(),
      row_pose.rotation.conjugate() *
          camera.ImageToWorld(pixel).homogeneous().normalized(),
      &hit));
  const Eigen::Vector3d point = hit.point;
  Eigen::Vector2d rolling;
  ASSERT_TRUE(ProjectWithRollingShutter(camera, capture, point, &rolling));
  EXPECT_LT((rolling - pixel).norm(), 1e-6);
  const Rigid3d top_pose = capture.CamFromWorldAt(capture.top_row_time_s);
  const Eigen::Vector2d global =
      camera.WorldToImage((top_pose * point).hnormalized());
  // 180 rows of 100 us at the turn: the pose changed by several pixels.
  const double expected_shift = (global - rolling).norm();
  ASSERT_GT(expected_shift, 3.0);

  const std::vector<double> rolling_image = GreyLevels(RenderImage(
      scene, rays, CamFromWorldPerRow(capture, camera.Height()),
      GreyNoiseless(), 0));
  const std::vector<double> at_row_time =
      GreyLevels(RenderImage(scene, rays, row_pose, GreyNoiseless(), 0));
  const std::vector<double> at_top_time =
      GreyLevels(RenderImage(scene, rays, top_pose, GreyNoiseless(), 0));
  double score = 0;
  // Searched from the global-shutter projection, found at the rolling one.
  const Eigen::Vector2d found =
      FindPatch(at_row_time, 320, pixel, rolling_image, 320, global,
                expected_shift + 3, &score);
  std::cout << "rolling-shutter projection " << rolling.transpose()
            << ", global-shutter (top row) " << global.transpose()
            << ", found " << found.transpose() << " (NCC " << score << ")"
            << std::endl;
  EXPECT_GT(score, 0.9);
  EXPECT_LT((found - rolling).norm(), 0.25);
  // The same patch in the global-shutter image at the top row's time lies at
  // the global-shutter projection: the difference is the expected one.
  const Eigen::Vector2d found_global =
      FindPatch(at_row_time, 320, pixel, at_top_time, 320, rolling,
                expected_shift + 3, &score);
  EXPECT_GT(score, 0.9);
  EXPECT_LT((found_global - global).norm(), 0.25);
  EXPECT_NEAR((found_global - found).norm(), expected_shift, 0.35);
}

// With a capture-time offset and no line delay every row has the pose at the
// shifted time: the image is the global-shutter image at t_f + delta_c, bit
// for bit, and not the one at t_f.
TEST(SceneRenderer, OffsetOnlyCaptureIsTheGlobalShutterImageAtItsTime) {
  const TexturedScene scene = TexturedScene::Make(SceneType::kRoom, 3);
  MovingCamera moving(Eigen::Vector3d(1.5, -0.3, 1.5), 1.5, 60);
  ImageCapture& capture = moving.capture;
  const double frameset_time_s = capture.top_row_time_s;
  capture.top_row_time_s += 0.03;  // delta_c = 30 ms
  const CameraRays rays(moving.camera, 2);
  RenderOptions options;  // RGB with noise
  const std::vector<uint8_t> offset_only =
      RenderImage(scene, rays,
                  CamFromWorldPerRow(capture, moving.camera.Height()), options,
                  5)
          .ConvertToRowMajorArray();
  EXPECT_EQ(offset_only, RenderImage(scene, rays,
                                     capture.CamFromWorldAt(frameset_time_s +
                                                            0.03),
                                     options, 5)
                             .ConvertToRowMajorArray());
  EXPECT_NE(offset_only,
            RenderImage(scene, rays, capture.CamFromWorldAt(frameset_time_s),
                        options, 5)
                .ConvertToRowMajorArray());
  // One pose per row is required.
  EXPECT_EQ(RenderImage(scene, rays, std::vector<Rigid3d>(3), options, 5)
                .Width(),
            0);
}

}  // namespace scene_renderer_test
}  // namespace rig_calibrator
