#include "src/camera_upgrader.h"

#include <colmap/base/camera_models.h>
#include <colmap/util/random.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "src/rigid3d.h"

namespace rig_calibrator {
namespace {

constexpr double kPi = 3.14159265358979323846;

colmap::Camera MakeCamera(const std::string& model_name, const int width,
                          const int height, const std::vector<double>& params) {
  colmap::Camera camera;
  camera.SetModelIdFromName(model_name);
  camera.SetWidth(width);
  camera.SetHeight(height);
  camera.SetParams(params);
  return camera;
}

struct SceneOptions {
  int num_points = 400;
  double max_ray_angle_deg = 60;  // rays are drawn within this cone
  double min_distance = 2;
  double max_distance = 10;
  double noise_px = 0;
  double outlier_ratio = 0;
  unsigned seed = 1;
};

// Correspondences of a camera with a random cam_from_world whose tz the
// upgrade must find: points at min..max_distance along rays drawn uniformly
// in a cone around the optical axis, kept if they project into the image.
struct Scene {
  double tz = 0;
  std::vector<Eigen::Vector2d> points2D;
  std::vector<Eigen::Vector3d> points_cam;  // R X + (tx, ty, 0)
  std::vector<char> is_outlier;
};

Scene MakeScene(const colmap::Camera& camera, const SceneOptions& options) {
  std::mt19937 generator(options.seed);
  std::uniform_real_distribution<double> uniform(0, 1);
  std::normal_distribution<double> normal(0, 1);
  const Eigen::Quaterniond rotation = Eigen::Quaterniond(
      normal(generator), normal(generator), normal(generator),
      normal(generator));
  const Rigid3d cam_from_world(
      rotation, Eigen::Vector3d(2 * uniform(generator) - 1,
                                2 * uniform(generator) - 1,
                                2 * uniform(generator) - 1));
  const Rigid3d world_from_cam = cam_from_world.Inverse();

  Scene scene;
  scene.tz = cam_from_world.translation.z();
  const double min_cos = std::cos(options.max_ray_angle_deg * kPi / 180);
  while (static_cast<int>(scene.points2D.size()) < options.num_points) {
    const double cos_theta = min_cos + (1 - min_cos) * uniform(generator);
    const double sin_theta = std::sqrt(1 - cos_theta * cos_theta);
    const double phi = 2 * kPi * uniform(generator);
    const double distance =
        options.min_distance +
        (options.max_distance - options.min_distance) * uniform(generator);
    const Eigen::Vector3d point_in_cam =
        distance * Eigen::Vector3d(sin_theta * std::cos(phi),
                                   sin_theta * std::sin(phi), cos_theta);
    Eigen::Vector2d point2D;
    colmap::CameraModelWorldToImage(
        camera.ModelId(), camera.Params(), point_in_cam.x() / point_in_cam.z(),
        point_in_cam.y() / point_in_cam.z(), &point2D.x(), &point2D.y());
    if (point2D.x() < 0 || point2D.y() < 0 || point2D.x() > camera.Width() ||
        point2D.y() > camera.Height()) {
      continue;
    }
    const Eigen::Vector3d point3D = world_from_cam * point_in_cam;
    Eigen::Vector3d point_cam = cam_from_world * point3D;
    point_cam.z() -= scene.tz;
    const bool is_outlier = uniform(generator) < options.outlier_ratio;
    if (is_outlier) {
      Eigen::Vector2d wrong;
      do {
        wrong = Eigen::Vector2d(camera.Width() * uniform(generator),
                                camera.Height() * uniform(generator));
      } while ((wrong - point2D).norm() < 20);
      point2D = wrong;
    } else {
      point2D += options.noise_px *
                 Eigen::Vector2d(normal(generator), normal(generator));
    }
    scene.points2D.push_back(point2D);
    scene.points_cam.push_back(point_cam);
    scene.is_outlier.push_back(is_outlier);
  }
  return scene;
}

// The input camera: the true model and size, the principal point off by
// `principal_point_error` px, every other parameter wrong.
colmap::Camera MakeInputCamera(const colmap::Camera& truth,
                               const Eigen::Vector2d& principal_point_error) {
  colmap::Camera camera = truth;
  for (double& param : camera.Params()) {
    param = 0.5;
  }
  camera.SetPrincipalPointX(truth.PrincipalPointX() +
                            principal_point_error.x());
  camera.SetPrincipalPointY(truth.PrincipalPointY() +
                            principal_point_error.y());
  return camera;
}

struct ModelCase {
  std::string model_name;
  std::vector<double> params;  // 640 x 480, principal point off by (15, -12)
  double max_ray_angle_deg;
};

std::vector<ModelCase> AllModelCases() {
  return {
      {"SIMPLE_PINHOLE", {500, 335, 228}, 60},
      {"PINHOLE", {500, 503, 335, 228}, 60},
      {"SIMPLE_RADIAL", {500, 335, 228, -0.15}, 60},
      {"RADIAL", {500, 335, 228, -0.3, 0.08}, 60},
      {"OPENCV", {500, 502, 335, 228, -0.3, 0.08, 0.001, -0.0015}, 60},
      {"FULL_OPENCV",
       {500, 502, 335, 228, -0.3, 0.08, 0.001, -0.0015, -0.01, 0.02, -0.005,
        0.001},
       60},
      {"SIMPLE_RADIAL_FISHEYE", {300, 335, 228, 0.03}, 75},
      {"RADIAL_FISHEYE", {300, 335, 228, 0.03, -0.005}, 75},
      {"OPENCV_FISHEYE",
       {300, 302, 335, 228, 0.02, -0.005, 0.002, -0.0005},
       75},
      {"THIN_PRISM_FISHEYE",
       {300, 302, 335, 228, 0.02, -0.005, 0.0005, -0.0003, 0.002, -0.0005,
        0.0004, -0.0002},
       75},
  };
}

TEST(CameraUpgrader, ExactDataRecoversEveryModel) {
  for (const ModelCase& model_case : AllModelCases()) {
    SCOPED_TRACE(model_case.model_name);
    const colmap::Camera truth =
        MakeCamera(model_case.model_name, 640, 480, model_case.params);
    SceneOptions scene_options;
    scene_options.max_ray_angle_deg = model_case.max_ray_angle_deg;
    const Scene scene = MakeScene(truth, scene_options);
    colmap::Camera camera = MakeInputCamera(truth, Eigen::Vector2d(4, -3));

    CameraUpgradeResult result;
    ASSERT_TRUE(UpgradeCamera(CameraUpgradeOptions(), scene.points2D,
                              scene.points_cam, &camera, &result))
        << result.error_message;
    EXPECT_EQ(result.num_inliers, scene_options.num_points);
    std::cout << model_case.model_name << " tz err " << result.tz - scene.tz
              << " rms " << result.rms_px << " corr "
              << result.tz_focal_correlation << " well "
              << result.well_conditioned << "\n";
    for (size_t i = 0; i < truth.NumParams(); ++i) {
      std::cout << "  " << camera.Params()[i] << " err "
                << camera.Params()[i] - truth.Params()[i] << "\n";
    }
  }
}


TEST(CameraUpgrader, Explore) {
  const char* env = std::getenv("EXPLORE");
  if (env == nullptr) return;
  const std::string what = env;
  for (const ModelCase& model_case : AllModelCases()) {
    const colmap::Camera truth =
        MakeCamera(model_case.model_name, 640, 480, model_case.params);
    SceneOptions scene_options;
    scene_options.max_ray_angle_deg = model_case.max_ray_angle_deg;
    CameraUpgradeOptions options;
    Eigen::Vector2d pp_error(4, -3);
    if (what == "iter") {
      options.max_num_iterations = 2000;
    } else if (what == "noisy") {
      scene_options.num_points = 1000;
      scene_options.noise_px = 0.5;
      scene_options.outlier_ratio = 0.3;
    } else if (what == "center") {
      pp_error = Eigen::Vector2d(320, 240) - Eigen::Vector2d(truth.PrincipalPointX(), truth.PrincipalPointY());  
    } else if (what == "single") {
      scene_options.num_points = 150;
      scene_options.noise_px = 0.5;
      scene_options.outlier_ratio = 0.2;
    } else if (what == "big") {
      scene_options.num_points = 100000;
      scene_options.noise_px = 0.5;
      scene_options.outlier_ratio = 0.3;
    } else if (what == "narrow") {
      scene_options.min_distance = 9.9;
      scene_options.max_distance = 10.1;
      scene_options.max_ray_angle_deg = 5;
      scene_options.noise_px = 0.5;
    } else if (what == "mid") {
      scene_options.min_distance = 9;
      scene_options.max_distance = 11;
      scene_options.noise_px = 0.5;
    }
    const Scene scene = MakeScene(truth, scene_options);
    colmap::Camera camera = MakeInputCamera(truth, pp_error);
    CameraUpgradeResult result;
    const auto start = std::chrono::steady_clock::now();
    const bool ok = UpgradeCamera(options, scene.points2D, scene.points_cam, &camera, &result);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    int tp = 0, fp = 0, n_in = 0;
    for (size_t i = 0; i < scene.is_outlier.size(); ++i) {
      n_in += !scene.is_outlier[i];
      if (result.inlier_mask.size() && result.inlier_mask[i]) { if (scene.is_outlier[i]) ++fp; else ++tp; }
    }
    std::cout << model_case.model_name << " ok " << ok << " " << secs << " s tz err " << result.tz - scene.tz
              << " rms " << result.rms_px << " corr " << result.tz_focal_correlation << " well "
              << result.well_conditioned << " sd_tz " << result.tz_stddev << " sd_f " << result.focal_stddev_px
              << " inl " << tp << "/" << n_in << " fp " << fp << "\n";
    if (!ok) { std::cout << result.error_message << "\n"; continue; }
    for (size_t i = 0; i < truth.NumParams(); ++i) {
      std::cout << "  " << camera.Params()[i] << " err " << camera.Params()[i] - truth.Params()[i] << "\n";
    }
  }
}

}  // namespace
}  // namespace rig_calibrator
