#include "src/calibration/camera_upgrader.h"

#include <colmap/base/camera_models.h>
#include <colmap/util/random.h>
#include <glog/logging.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "src/geometry/rigid3d.h"

namespace rig_calibrator {
namespace camera_upgrader_test {

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
  const Eigen::Quaterniond rotation =
      Eigen::Quaterniond(normal(generator), normal(generator),
                         normal(generator), normal(generator));
  const Rigid3d cam_from_world(
      rotation,
      Eigen::Vector3d(2 * uniform(generator) - 1, 2 * uniform(generator) - 1,
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

// Tolerances on exact data: the focal lengths relative, the principal point
// in pixels, distortion absolute. FULL_OPENCV's rational distortion
// (1 + k1 r^2 + k2 r^4 + k3 r^6) / (1 + k4 r^2 + k5 r^4 + k6 r^6) is nearly
// unchanged when numerator and denominator gain a common factor, so its
// terms stop at ~2.5e-6 (measured) with the reprojection error at 4e-10 px.
constexpr double kFocalRelativeTolerance = 1e-8;
constexpr double kPrincipalPointTolerancePx = 1e-6;
constexpr double kDistortionTolerance = 1e-8;
constexpr double kRationalDistortionTolerance = 1e-5;

void ExpectFocalAndPrincipalPointNear(const colmap::Camera& camera,
                                      const colmap::Camera& truth,
                                      const double focal_relative_tolerance,
                                      const double principal_point_tolerance) {
  ASSERT_EQ(camera.NumParams(), truth.NumParams());
  for (const size_t i : truth.FocalLengthIdxs()) {
    EXPECT_NEAR(camera.Params()[i], truth.Params()[i],
                focal_relative_tolerance * truth.Params()[i]);
  }
  for (const size_t i : truth.PrincipalPointIdxs()) {
    EXPECT_NEAR(camera.Params()[i], truth.Params()[i],
                principal_point_tolerance);
  }
}

void ExpectParamsNear(const colmap::Camera& camera, const colmap::Camera& truth,
                      const double focal_relative_tolerance,
                      const double principal_point_tolerance_px,
                      const double distortion_tolerance) {
  ExpectFocalAndPrincipalPointNear(camera, truth, focal_relative_tolerance,
                                   principal_point_tolerance_px);
  for (const size_t i : truth.ExtraParamsIdxs()) {
    EXPECT_NEAR(camera.Params()[i], truth.Params()[i], distortion_tolerance)
        << "parameter " << i;
  }
}

// At least `min_inlier_recall` of the true inliers are inliers and at most
// `max_outlier_share` of the wrong matches.
void ExpectInliersRecovered(const Scene& scene,
                            const CameraUpgradeResult& result,
                            const double min_inlier_recall,
                            const double max_outlier_share) {
  ASSERT_EQ(result.inlier_mask.size(), scene.is_outlier.size());
  int num_true_inliers = 0, num_found_inliers = 0;
  int num_outliers = 0, num_accepted_outliers = 0;
  for (size_t i = 0; i < scene.is_outlier.size(); ++i) {
    if (scene.is_outlier[i]) {
      ++num_outliers;
      num_accepted_outliers += result.inlier_mask[i];
    } else {
      ++num_true_inliers;
      num_found_inliers += result.inlier_mask[i];
    }
  }
  EXPECT_EQ(result.num_inliers, num_found_inliers + num_accepted_outliers);
  EXPECT_GE(num_found_inliers, min_inlier_recall * num_true_inliers);
  EXPECT_LE(num_accepted_outliers, max_outlier_share * num_outliers);
}

// The scene of a model case: rays within its cone, the other options as
// given.
SceneOptions SceneOptionsFor(const ModelCase& model_case) {
  SceneOptions options;
  options.max_ray_angle_deg = model_case.max_ray_angle_deg;
  return options;
}

// 0.5 px noise and `outlier_ratio` wrong matches.
SceneOptions NoisySceneOptionsFor(const ModelCase& model_case,
                                  const int num_points,
                                  const double outlier_ratio,
                                  const unsigned seed = 1) {
  SceneOptions options = SceneOptionsFor(model_case);
  options.num_points = num_points;
  options.noise_px = 0.5;
  options.outlier_ratio = outlier_ratio;
  options.seed = seed;
  return options;
}

const ModelCase& FindModelCase(const std::string& model_name) {
  static const std::vector<ModelCase> model_cases = AllModelCases();
  for (const ModelCase& model_case : model_cases) {
    if (model_case.model_name == model_name) return model_case;
  }
  LOG(FATAL) << "no model case " << model_name;
  return model_cases[0];
}

// One upgrade of a camera of `model_case` (640 x 480) from the scene of
// `scene_options`, the input camera's principal point off by
// `principal_point_error`; `success` is UpgradeCamera's return value.
struct Upgrade {
  colmap::Camera truth;
  Scene scene;
  colmap::Camera camera;
  CameraUpgradeResult result;
  bool success = false;
};

Upgrade RunUpgrade(
    const ModelCase& model_case, const SceneOptions& scene_options,
    const Eigen::Vector2d& principal_point_error,
    const CameraUpgradeOptions& options = CameraUpgradeOptions()) {
  Upgrade upgrade;
  upgrade.truth =
      MakeCamera(model_case.model_name, 640, 480, model_case.params);
  upgrade.scene = MakeScene(upgrade.truth, scene_options);
  upgrade.camera = MakeInputCamera(upgrade.truth, principal_point_error);
  upgrade.success =
      UpgradeCamera(options, upgrade.scene.points2D, upgrade.scene.points_cam,
                    &upgrade.camera, &upgrade.result);
  return upgrade;
}

// An upgrade on exact data: every point an inlier, no residual, tz and the
// parameters at the truth.
void ExpectExactRecovery(const Upgrade& upgrade, int num_points,
                         double distortion_tolerance) {
  ASSERT_TRUE(upgrade.success) << upgrade.result.error_message;
  EXPECT_EQ(upgrade.result.num_inliers, num_points);
  EXPECT_LT(upgrade.result.rms_px, 1e-8);
  EXPECT_TRUE(upgrade.result.well_conditioned);
  EXPECT_NEAR(upgrade.result.tz, upgrade.scene.tz, 1e-8);
  ExpectParamsNear(upgrade.camera, upgrade.truth, kFocalRelativeTolerance,
                   kPrincipalPointTolerancePx, distortion_tolerance);
}

// Exact data: tz and every parameter of every supported model.
TEST(CameraUpgrader, ExactDataRecoversEveryModel) {
  for (const ModelCase& model_case : AllModelCases()) {
    SCOPED_TRACE(model_case.model_name);
    const SceneOptions scene_options = SceneOptionsFor(model_case);
    const Upgrade upgrade =
        RunUpgrade(model_case, scene_options, Eigen::Vector2d(4, -3));
    ExpectExactRecovery(upgrade, scene_options.num_points,
                        model_case.model_name == "FULL_OPENCV"
                            ? kRationalDistortionTolerance
                            : kDistortionTolerance);
  }
}

// A principal point guess at the image center, 19 px from the truth.
TEST(CameraUpgrader, ExactDataFromImageCenter) {
  for (const std::string model_name : {"OPENCV", "OPENCV_FISHEYE"}) {
    SCOPED_TRACE(model_name);
    const ModelCase& model_case = FindModelCase(model_name);
    const SceneOptions scene_options = SceneOptionsFor(model_case);
    // The truth's principal point is at (335, 228).
    const Upgrade upgrade = RunUpgrade(model_case, scene_options,
                                       Eigen::Vector2d(320 - 335, 240 - 228));
    ASSERT_TRUE(upgrade.success) << upgrade.result.error_message;
    EXPECT_EQ(upgrade.result.num_inliers, scene_options.num_points);
    EXPECT_NEAR(upgrade.result.tz, upgrade.scene.tz, 1e-8);
    ExpectParamsNear(upgrade.camera, upgrade.truth, kFocalRelativeTolerance,
                     kPrincipalPointTolerancePx, kDistortionTolerance);
  }
}

// 0.5 px noise and 30% wrong matches, pooled frames (1000 correspondences).
// Measured: focal <= 0.08%, principal point <= 0.05 px, tz <= 1.5 mm (its
// 1-sigma uncertainty is ~1.5 mm), every inlier found, no outlier accepted.
TEST(CameraUpgrader, NoisyDataWithOutliers) {
  for (const ModelCase& model_case : AllModelCases()) {
    SCOPED_TRACE(model_case.model_name);
    const Upgrade upgrade =
        RunUpgrade(model_case, NoisySceneOptionsFor(model_case, 1000, 0.3),
                   Eigen::Vector2d(4, -3));
    ASSERT_TRUE(upgrade.success) << upgrade.result.error_message;
    const CameraUpgradeResult& result = upgrade.result;
    ExpectInliersRecovered(upgrade.scene, result, 0.99, 0.005);
    // 0.5 px per coordinate: 0.71 px in 2D.
    EXPECT_GT(result.rms_px, 0.6);
    EXPECT_LT(result.rms_px, 0.8);
    EXPECT_NEAR(result.tz, upgrade.scene.tz, 0.005);
    ExpectFocalAndPrincipalPointNear(upgrade.camera, upgrade.truth, 0.002, 1.0);
    EXPECT_TRUE(result.well_conditioned);
    EXPECT_LT(std::abs(result.tz_focal_correlation), 0.95);
    EXPECT_GT(result.focal_stddev_at_1px, 0);
    EXPECT_LT(result.focal_stddev_at_1px,
              0.01 * upgrade.camera.MeanFocalLength());
  }
}

// The `rd` baseline upgrades single images: 150 correspondences, 0.5 px
// noise, 20% wrong matches. Measured: focal <= 0.34% (fisheye models; the
// others <= 0.26%), principal point <= 0.09 px, tz <= 2.4 mm.
TEST(CameraUpgrader, SingleImage) {
  for (const ModelCase& model_case : AllModelCases()) {
    SCOPED_TRACE(model_case.model_name);
    const Upgrade upgrade =
        RunUpgrade(model_case, NoisySceneOptionsFor(model_case, 150, 0.2, 2),
                   Eigen::Vector2d(4, -3));
    ASSERT_TRUE(upgrade.success) << upgrade.result.error_message;
    ExpectInliersRecovered(upgrade.scene, upgrade.result, 0.97, 0.02);
    EXPECT_NEAR(upgrade.result.tz, upgrade.scene.tz, 0.02);
    ExpectFocalAndPrincipalPointNear(upgrade.camera, upgrade.truth, 0.005, 1.0);
  }
}

// Points all at 9.9-10.1 m in a 5 degree cone: only f / (c + tz) is
// observed. Measured: correlation >= 0.995, focal stddev at 1 px >= 110 px.
TEST(CameraUpgrader, EqualDepthsNarrowViewIsPoorlyConditioned) {
  for (const std::string model_name :
       {"SIMPLE_PINHOLE", "OPENCV", "OPENCV_FISHEYE"}) {
    SCOPED_TRACE(model_name);
    SceneOptions scene_options;
    scene_options.max_ray_angle_deg = 5;
    scene_options.min_distance = 9.9;
    scene_options.max_distance = 10.1;
    scene_options.noise_px = 0.5;
    const Upgrade upgrade = RunUpgrade(FindModelCase(model_name), scene_options,
                                       Eigen::Vector2d(1, -1));
    ASSERT_TRUE(upgrade.success) << upgrade.result.error_message;
    EXPECT_FALSE(upgrade.result.well_conditioned);
    EXPECT_GT(std::abs(upgrade.result.tz_focal_correlation), 0.99);
    EXPECT_GT(upgrade.result.focal_stddev_at_1px,
              0.1 * upgrade.camera.MeanFocalLength());
  }
}

// A camera pooled over many frames: RANSAC on a subset, inliers on all.
TEST(CameraUpgrader, RansacOnSubsetOfManyPoints) {
  const ModelCase& model_case = FindModelCase("OPENCV_FISHEYE");
  CameraUpgradeOptions options;
  options.max_num_ransac_points = 1000;
  const Upgrade upgrade =
      RunUpgrade(model_case, NoisySceneOptionsFor(model_case, 20000, 0.3),
                 Eigen::Vector2d(4, -3), options);
  ASSERT_TRUE(upgrade.success) << upgrade.result.error_message;
  ExpectInliersRecovered(upgrade.scene, upgrade.result, 0.99, 0.001);
  EXPECT_NEAR(upgrade.result.tz, upgrade.scene.tz, 0.002);
  ExpectFocalAndPrincipalPointNear(upgrade.camera, upgrade.truth, 0.0005, 0.1);
}

// The final LM on 200 of 2000 exact correspondences: the truth as from all.
TEST(CameraUpgrader, SubsampledRefinementExactData) {
  CameraUpgradeOptions options;
  options.max_num_refinement_points = 200;
  for (const std::string model_name : {"OPENCV", "OPENCV_FISHEYE"}) {
    SCOPED_TRACE(model_name);
    const ModelCase& model_case = FindModelCase(model_name);
    SceneOptions scene_options = SceneOptionsFor(model_case);
    scene_options.num_points = 2000;
    const Upgrade upgrade =
        RunUpgrade(model_case, scene_options, Eigen::Vector2d(4, -3), options);
    ExpectExactRecovery(upgrade, scene_options.num_points, kDistortionTolerance);
  }
}

// 0.5 px noise, 30 % wrong matches, 4000 correspondences (~2800 inliers):
// the final LM on 1000 of the inliers against all of them. Both estimate the
// same parameters from nested data, the full one efficiently, so their
// difference has variance var_sub - var_full = var_full (n / m - 1); tz and f
// must agree within 4 of its sigmas, sigma_full = 0.5 px * stddev_at_1px.
// The subsample's conditioning, scaled by m / n, must be that of all the
// inliers within 10 %. Measured: tz and f <= 1.4 sigmas apart, stddevs
// <= 5 % apart, correlations <= 0.015 apart.
TEST(CameraUpgrader, SubsampledRefinementNoisyDataMatchesAll) {
  constexpr double kNoisePx = 0.5;
  for (const std::string model_name : {"OPENCV", "OPENCV_FISHEYE"}) {
    SCOPED_TRACE(model_name);
    const ModelCase& model_case = FindModelCase(model_name);
    const SceneOptions scene_options =
        NoisySceneOptionsFor(model_case, 4000, 0.3);
    CameraUpgradeOptions all_options;
    all_options.max_num_refinement_points = scene_options.num_points;
    CameraUpgradeOptions subsample_options;
    subsample_options.max_num_refinement_points = 1000;
    const Upgrade all = RunUpgrade(model_case, scene_options,
                                   Eigen::Vector2d(4, -3), all_options);
    const Upgrade subsample = RunUpgrade(
        model_case, scene_options, Eigen::Vector2d(4, -3), subsample_options);
    ASSERT_TRUE(all.success) << all.result.error_message;
    ASSERT_TRUE(subsample.success) << subsample.result.error_message;
    ExpectInliersRecovered(subsample.scene, subsample.result, 0.99, 0.005);

    const double sqrt_ratio_minus_1 =
        std::sqrt(static_cast<double>(all.result.num_inliers) /
                      subsample_options.max_num_refinement_points -
                  1);
    const double tz_sigma =
        kNoisePx * all.result.tz_stddev_at_1px * sqrt_ratio_minus_1;
    const double focal_sigma =
        kNoisePx * all.result.focal_stddev_at_1px * sqrt_ratio_minus_1;
    EXPECT_NEAR(subsample.result.tz, all.result.tz, 4 * tz_sigma);
    EXPECT_NEAR(subsample.camera.MeanFocalLength(),
                all.camera.MeanFocalLength(), 4 * focal_sigma);
    std::cout << model_name << ": tz "
              << std::abs(subsample.result.tz - all.result.tz) / tz_sigma
              << " sigmas, f "
              << std::abs(subsample.camera.MeanFocalLength() -
                          all.camera.MeanFocalLength()) /
                     focal_sigma
              << " sigmas apart; stddev ratios tz "
              << subsample.result.tz_stddev_at_1px / all.result.tz_stddev_at_1px
              << ", f "
              << subsample.result.focal_stddev_at_1px /
                     all.result.focal_stddev_at_1px
              << ", correlations " << subsample.result.tz_focal_correlation
              << " / " << all.result.tz_focal_correlation << "\n";

    EXPECT_NEAR(subsample.result.tz_stddev_at_1px, all.result.tz_stddev_at_1px,
                0.1 * all.result.tz_stddev_at_1px);
    EXPECT_NEAR(subsample.result.focal_stddev_at_1px,
                all.result.focal_stddev_at_1px,
                0.1 * all.result.focal_stddev_at_1px);
    EXPECT_NEAR(subsample.result.tz_focal_correlation,
                all.result.tz_focal_correlation, 0.05);
    EXPECT_EQ(subsample.result.well_conditioned, all.result.well_conditioned);
  }
}

// Which rows the final LM uses: of 2000 inliers with 200 to keep, every 10th
// (rows 0, 10, 20, ...). Those are exact; every other row is off by 1 px,
// well within the inlier threshold. From the exact rows alone the truth is
// recovered; all rows (the option at 2000) pull the principal point by
// 0.95 px (measured).
TEST(CameraUpgrader, SubsampledRefinementUsesEvenlySpacedInliers) {
  const ModelCase& model_case = FindModelCase("OPENCV");
  const colmap::Camera truth =
      MakeCamera(model_case.model_name, 640, 480, model_case.params);
  SceneOptions scene_options = SceneOptionsFor(model_case);
  scene_options.num_points = 2000;
  Scene scene = MakeScene(truth, scene_options);
  for (size_t i = 0; i < scene.points2D.size(); ++i) {
    if (i % 10 != 0) scene.points2D[i].x() += 1;
  }
  for (const int max_num_refinement_points : {200, 2000}) {
    SCOPED_TRACE(max_num_refinement_points);
    CameraUpgradeOptions options;
    options.max_num_refinement_points = max_num_refinement_points;
    colmap::Camera camera = MakeInputCamera(truth, Eigen::Vector2d(4, -3));
    CameraUpgradeResult result;
    ASSERT_TRUE(UpgradeCamera(options, scene.points2D, scene.points_cam,
                              &camera, &result))
        << result.error_message;
    EXPECT_EQ(result.num_inliers, scene_options.num_points);
    if (max_num_refinement_points == 200) {
      EXPECT_NEAR(result.tz, scene.tz, 1e-8);
      ExpectParamsNear(camera, truth, kFocalRelativeTolerance,
                       kPrincipalPointTolerancePx, kDistortionTolerance);
    } else {
      EXPECT_GT(std::abs(camera.PrincipalPointX() - truth.PrincipalPointX()),
                0.5);
    }
  }
}

TEST(CameraUpgrader, FixedPrincipalPoint) {
  const ModelCase& model_case = FindModelCase("RADIAL");
  CameraUpgradeOptions options;
  options.refine_principal_point = false;
  const Upgrade upgrade = RunUpgrade(model_case, SceneOptionsFor(model_case),
                                     Eigen::Vector2d::Zero(), options);
  ASSERT_TRUE(upgrade.success) << upgrade.result.error_message;
  EXPECT_EQ(upgrade.camera.PrincipalPointX(), upgrade.truth.PrincipalPointX());
  EXPECT_EQ(upgrade.camera.PrincipalPointY(), upgrade.truth.PrincipalPointY());
  EXPECT_NEAR(upgrade.result.tz, upgrade.scene.tz, 1e-8);
  ExpectParamsNear(upgrade.camera, upgrade.truth, kFocalRelativeTolerance,
                   kPrincipalPointTolerancePx, kDistortionTolerance);

  // With a wrong fixed principal point the other parameters compensate
  // only partly.
  const Upgrade shifted = RunUpgrade(model_case, SceneOptionsFor(model_case),
                                     Eigen::Vector2d(3, 0), options);
  ASSERT_TRUE(shifted.success);
  EXPECT_EQ(shifted.camera.PrincipalPointX(),
            shifted.truth.PrincipalPointX() + 3);
  EXPECT_GT(shifted.result.rms_px, 0.1);
}

// COLMAP's refine_focal_length / refine_extra_params 0: exact data, the held
// parameters given at the truth stay exactly there and tz and the other
// parameters are recovered; a held focal length 2 % off stays exactly at
// the given value (tz and the distortion absorb what they can).
TEST(CameraUpgrader, HeldFocalLengthAndDistortion) {
  for (const std::string model_name :
       {"SIMPLE_RADIAL", "OPENCV", "OPENCV_FISHEYE"}) {
    const ModelCase& model_case = FindModelCase(model_name);
    const colmap::Camera truth =
        MakeCamera(model_case.model_name, 640, 480, model_case.params);
    const Scene scene = MakeScene(truth, SceneOptionsFor(model_case));
    for (const bool hold_focal : {true, false}) {
      SCOPED_TRACE(model_name + (hold_focal ? " focal" : " distortion"));
      CameraUpgradeOptions options;
      options.refine_focal_length = !hold_focal;
      options.refine_extra_params = hold_focal;
      colmap::Camera camera = MakeInputCamera(truth, Eigen::Vector2d(0, 0));
      const std::vector<size_t>& held =
          hold_focal ? truth.FocalLengthIdxs() : truth.ExtraParamsIdxs();
      for (const size_t i : held) camera.Params(i) = truth.Params(i);
      CameraUpgradeResult result;
      ASSERT_TRUE(UpgradeCamera(options, scene.points2D, scene.points_cam,
                                &camera, &result))
          << result.error_message;
      for (const size_t i : held) {
        EXPECT_EQ(camera.Params(i), truth.Params(i)) << "param " << i;
      }
      EXPECT_NEAR(result.tz, scene.tz, 1e-8);
      ExpectParamsNear(camera, truth, kFocalRelativeTolerance,
                       kPrincipalPointTolerancePx, kDistortionTolerance);
      EXPECT_LT(result.rms_px, 1e-6);
    }
    colmap::Camera off = MakeInputCamera(truth, Eigen::Vector2d(0, 0));
    for (const size_t i : truth.FocalLengthIdxs()) {
      off.Params(i) = 1.02 * truth.Params(i);
    }
    const std::vector<double> given = off.Params();
    CameraUpgradeOptions options;
    options.refine_focal_length = false;
    CameraUpgradeResult result;
    ASSERT_TRUE(
        UpgradeCamera(options, scene.points2D, scene.points_cam, &off, &result))
        << model_name << ": " << result.error_message;
    for (const size_t i : truth.FocalLengthIdxs()) {
      EXPECT_EQ(off.Params(i), given[i]) << model_name;
    }
  }
}

// Fractions of the true inliers found and of the wrong matches accepted.
struct InlierRecall {
  double inliers = 0;
  double outliers = 0;
};

InlierRecall ComputeInlierRecall(const Scene& scene,
                                 const CameraUpgradeResult& result) {
  int num_true_inliers = 0, num_found_inliers = 0;
  int num_outliers = 0, num_accepted_outliers = 0;
  for (size_t i = 0; i < scene.is_outlier.size(); ++i) {
    (scene.is_outlier[i] ? num_outliers : num_true_inliers) += 1;
    (scene.is_outlier[i] ? num_accepted_outliers : num_found_inliers) +=
        result.inlier_mask[i];
  }
  return {static_cast<double>(num_found_inliers) / num_true_inliers,
          static_cast<double>(num_accepted_outliers) / num_outliers};
}

// The models of the held-focal tests: both profiles, 0 to 2 radial terms in
// the RANSAC, one and two focal lengths.
const std::vector<std::string> kHeldFocalModels = {
    "SIMPLE_PINHOLE", "SIMPLE_RADIAL",         "RADIAL",
    "OPENCV",         "SIMPLE_RADIAL_FISHEYE", "OPENCV_FISHEYE"};

// The upgrade of `model_case`'s noisy scene with the focal length held at
// `focal_scale` times the truth.
Upgrade RunHeldFocalUpgrade(const ModelCase& model_case,
                            const SceneOptions& scene_options,
                            const double focal_scale) {
  Upgrade upgrade;
  upgrade.truth =
      MakeCamera(model_case.model_name, 640, 480, model_case.params);
  upgrade.scene = MakeScene(upgrade.truth, scene_options);
  upgrade.camera = MakeInputCamera(upgrade.truth, Eigen::Vector2d(4, -3));
  for (const size_t i : upgrade.truth.FocalLengthIdxs()) {
    upgrade.camera.Params(i) = focal_scale * upgrade.truth.Params(i);
  }
  CameraUpgradeOptions options;
  options.refine_focal_length = false;
  upgrade.success =
      UpgradeCamera(options, upgrade.scene.points2D, upgrade.scene.points_cam,
                    &upgrade.camera, &upgrade.result);
  return upgrade;
}

// RunHeldFocalUpgrade for every model of kHeldFocalModels with 30 % and 50 %
// wrong matches on 1000 correspondences; each successful upgrade holds the
// scaled focal length bit for bit, then goes to check(model, outlier ratio,
// upgrade).
template <typename Check>
void ForEachHeldFocalUpgrade(const double focal_scale, const Check& check) {
  for (const std::string& model_name : kHeldFocalModels) {
    for (const double outlier_ratio : {0.3, 0.5}) {
      SCOPED_TRACE(model_name + " " + std::to_string(outlier_ratio));
      const ModelCase& model_case = FindModelCase(model_name);
      const Upgrade upgrade = RunHeldFocalUpgrade(
          model_case, NoisySceneOptionsFor(model_case, 1000, outlier_ratio),
          focal_scale);
      ASSERT_TRUE(upgrade.success) << upgrade.result.error_message;
      for (const size_t i : upgrade.truth.FocalLengthIdxs()) {
        EXPECT_EQ(upgrade.camera.Params(i),
                  focal_scale * upgrade.truth.Params(i));
      }
      check(model_name, outlier_ratio, upgrade);
    }
  }
}

// refine_focal_length 0 with the true focal length given, 0.5 px noise and
// 30 % or 50 % wrong matches on 1000 correspondences: the RANSAC with that
// f finds every inlier, f stays bit for bit, tz, the principal point and
// k1, k2 are recovered (printed). Measured: every inlier, no outlier,
// tz <= 0.8 mm, k1, k2 <= 0.0004 (0.0094 for OPENCV_FISHEYE at 50 %).
TEST(CameraUpgrader, HeldFocalLengthNoisyDataWithOutliers) {
  ForEachHeldFocalUpgrade(
      1.0, [](const std::string& model_name, const double outlier_ratio,
              const Upgrade& upgrade) {
        ExpectInliersRecovered(upgrade.scene, upgrade.result, 0.99, 0.005);
        EXPECT_NEAR(upgrade.result.tz, upgrade.scene.tz, 0.005);
        ExpectFocalAndPrincipalPointNear(upgrade.camera, upgrade.truth, 0, 1.0);
        double max_k_error = 0;
        const std::vector<size_t>& extra = upgrade.truth.ExtraParamsIdxs();
        for (size_t j = 0; j < std::min<size_t>(2, extra.size()); ++j) {
          max_k_error =
              std::max(max_k_error, std::abs(upgrade.camera.Params(extra[j]) -
                                             upgrade.truth.Params(extra[j])));
        }
        // With more distortion terms than k1, k2 (OPENCV's tangential,
        // OPENCV_FISHEYE's k3, k4) the LM trades k1, k2 against them.
        EXPECT_LT(max_k_error, extra.size() > 2 ? 0.02 : 0.005);
        const InlierRecall recall =
            ComputeInlierRecall(upgrade.scene, upgrade.result);
        std::cout << model_name << " f held, " << 100 * outlier_ratio
                  << " % outliers: inliers found " << 100 * recall.inliers
                  << " %, outliers accepted " << 100 * recall.outliers
                  << " %, |tz error| "
                  << std::abs(upgrade.result.tz - upgrade.scene.tz)
                  << " m, max |k1, k2 error| " << max_k_error << "\n";
      });
}

// refine_focal_length 0 with a given focal length 2 % off the truth, 0.5 px
// noise and 30 % or 50 % wrong matches: the upgrade holds it bit for bit and
// still finds >= 95 % of the true inliers (tz and the distortion absorb
// what they can of the wrong f), accepting <= 1 % of the wrong matches
// (printed). Measured: >= 99.5 % of the inliers, no outlier, RMS 0.87-2.15
// px.
TEST(CameraUpgrader, HeldWrongFocalLengthStillFindsTheInliers) {
  ForEachHeldFocalUpgrade(
      1.02, [](const std::string& model_name, const double outlier_ratio,
               const Upgrade& upgrade) {
        ExpectInliersRecovered(upgrade.scene, upgrade.result, 0.95, 0.01);
        const InlierRecall recall =
            ComputeInlierRecall(upgrade.scene, upgrade.result);
        std::cout << model_name << " f held 2 % off, " << 100 * outlier_ratio
                  << " % outliers: inliers found " << 100 * recall.inliers
                  << " %, outliers accepted " << 100 * recall.outliers
                  << " %, rms " << upgrade.result.rms_px << " px\n";
      });
}

// The result depends only on the input, not on COLMAP's random state: equal
// to the last bit after different seeds of COLMAP's generator.
TEST(CameraUpgrader, Deterministic) {
  const ModelCase& model_case = FindModelCase("OPENCV");
  const SceneOptions scene_options = NoisySceneOptionsFor(model_case, 400, 0.3);
  std::vector<Upgrade> upgrades;
  for (const unsigned seed : {1u, 2u}) {
    colmap::SetPRNGSeed(seed);
    upgrades.push_back(
        RunUpgrade(model_case, scene_options, Eigen::Vector2d(4, -3)));
    ASSERT_TRUE(upgrades.back().success);
  }
  EXPECT_EQ(upgrades[0].camera.Params(), upgrades[1].camera.Params());
  EXPECT_EQ(upgrades[0].result.tz, upgrades[1].result.tz);
  EXPECT_EQ(upgrades[0].result.inlier_mask, upgrades[1].result.inlier_mask);
}

TEST(CameraUpgrader, NonFiniteCorrespondencesAreOutliers) {
  const ModelCase& model_case = FindModelCase("SIMPLE_RADIAL");
  const colmap::Camera truth =
      MakeCamera(model_case.model_name, 640, 480, model_case.params);
  Scene scene = MakeScene(truth, SceneOptionsFor(model_case));
  scene.points2D[3].x() = std::numeric_limits<double>::quiet_NaN();
  scene.points_cam[7].z() = std::numeric_limits<double>::infinity();
  colmap::Camera camera = MakeInputCamera(truth, Eigen::Vector2d(4, -3));
  CameraUpgradeResult result;
  ASSERT_TRUE(UpgradeCamera(CameraUpgradeOptions(), scene.points2D,
                            scene.points_cam, &camera, &result))
      << result.error_message;
  EXPECT_EQ(result.num_inliers, static_cast<int>(scene.points2D.size()) - 2);
  EXPECT_FALSE(result.inlier_mask[3]);
  EXPECT_FALSE(result.inlier_mask[7]);
  EXPECT_NEAR(result.tz, scene.tz, 1e-8);
}

TEST(CameraUpgrader, RejectsUnsupportedModelAndBadInput) {
  const ModelCase& model_case = FindModelCase("RADIAL");
  const colmap::Camera truth =
      MakeCamera(model_case.model_name, 640, 480, model_case.params);
  const Scene scene = MakeScene(truth, SceneOptionsFor(model_case));
  CameraUpgradeResult result;

  colmap::Camera fov = MakeCamera("FOV", 640, 480, {500, 500, 320, 240, 0.1});
  const std::vector<double> fov_params = fov.Params();
  EXPECT_FALSE(IsUpgradeSupportedCameraModel(fov.ModelId()));
  EXPECT_FALSE(UpgradeCamera(CameraUpgradeOptions(), scene.points2D,
                             scene.points_cam, &fov, &result));
  EXPECT_NE(result.error_message.find("FOV"), std::string::npos);
  EXPECT_EQ(fov.Params(), fov_params);

  for (const ModelCase& model_case : AllModelCases()) {
    EXPECT_TRUE(IsUpgradeSupportedCameraModel(
        colmap::CameraModelNameToId(model_case.model_name)));
  }

  colmap::Camera camera = MakeInputCamera(truth, Eigen::Vector2d::Zero());
  const std::vector<double> params = camera.Params();
  // Sizes differ.
  EXPECT_FALSE(
      UpgradeCamera(CameraUpgradeOptions(), scene.points2D,
                    {scene.points_cam.begin(), scene.points_cam.end() - 1},
                    &camera, &result));
  // Too few correspondences.
  EXPECT_FALSE(
      UpgradeCamera(CameraUpgradeOptions(),
                    {scene.points2D.begin(), scene.points2D.begin() + 4},
                    {scene.points_cam.begin(), scene.points_cam.begin() + 4},
                    &camera, &result));
  // Invalid options.
  CameraUpgradeOptions options;
  options.max_error_px = 0;
  EXPECT_FALSE(UpgradeCamera(options, scene.points2D, scene.points_cam, &camera,
                             &result));
  options = CameraUpgradeOptions();
  options.max_num_refinement_points = 0;
  EXPECT_FALSE(UpgradeCamera(options, scene.points2D, scene.points_cam, &camera,
                             &result));
  EXPECT_NE(result.error_message.find("max_num_refinement_points"),
            std::string::npos);
  // Fewer refinement points than RADIAL's 6 unknowns (tz, f, c, k1, k2).
  options.max_num_refinement_points = 5;
  EXPECT_FALSE(UpgradeCamera(options, scene.points2D, scene.points_cam, &camera,
                             &result));
  EXPECT_NE(result.error_message.find("max_num_refinement_points"),
            std::string::npos);
  // Parameters that do not match the model.
  colmap::Camera wrong_params = camera;
  wrong_params.Params().pop_back();
  EXPECT_FALSE(UpgradeCamera(CameraUpgradeOptions(), scene.points2D,
                             scene.points_cam, &wrong_params, &result));
  // Every 3D point on the wrong half-line of the radial pose.
  std::vector<Eigen::Vector3d> flipped = scene.points_cam;
  for (Eigen::Vector3d& point : flipped) {
    point.x() = -point.x();
    point.y() = -point.y();
  }
  EXPECT_FALSE(UpgradeCamera(CameraUpgradeOptions(), scene.points2D, flipped,
                             &camera, &result));
  EXPECT_FALSE(result.error_message.empty());
  EXPECT_EQ(camera.Params(), params);
  EXPECT_FALSE(UpgradeCamera(CameraUpgradeOptions(), scene.points2D,
                             scene.points_cam, nullptr, &result));
}

}  // namespace camera_upgrader_test
}  // namespace rig_calibrator
