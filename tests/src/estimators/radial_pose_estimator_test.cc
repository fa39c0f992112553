#include "src/estimators/radial_pose_estimator.h"

#include <ceres/ceres.h>
#include <colmap/util/math.h>
#include <colmap/util/random.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <limits>
#include <random>
#include <vector>

#include "src/geometry/radial_error.h"
#include "src/geometry/radial_reprojection_cost.h"
#include "tests/src/solvers/radial_pose_test_scene.h"

namespace rig_calibrator {
namespace radial_pose_estimator_test {

constexpr double kFocalPx = 500;

struct Scene {
  Rigid3d cam_from_world;  // tz == 0, the radial pose
  std::vector<Eigen::Vector2d> points2D;
  std::vector<Eigen::Vector3d> points3D;
  std::vector<char> is_inlier;
  // Plane n.X = d of (near-)planar scenes, n == 0 otherwise.
  Eigen::Vector3d plane_normal = Eigen::Vector3d::Zero();
  double plane_offset = 0;
};

struct SceneOptions {
  int num_points = 300;
  double outlier_ratio = 0;
  double noise_px = 0;
  // Points within +-1e-3 m of a plane (exactly on it if planar_thickness 0).
  bool planar = false;
  double planar_thickness = 1e-3;
};

SceneOptions NoisyScene(int num_points, double noise_px, double outlier_ratio) {
  SceneOptions options;
  options.num_points = num_points;
  options.noise_px = noise_px;
  options.outlier_ratio = outlier_ratio;
  return options;
}

// A random camera (equidistant fisheye, f = 500 px, principal point at the
// origin) seeing points 2-10 m away up to 60 degrees off axis (image radius
// <= 524 px). Inliers get Gaussian noise; outliers a random pixel in the
// 1100 x 1100 image, away from their true line.
Scene MakeScene(const SceneOptions& options, std::mt19937* rng) {
  std::uniform_real_distribution<double> uniform(-1, 1);
  std::normal_distribution<double> normal;
  Scene scene;
  const Eigen::Quaterniond rotation = testing::RandomRotation(rng);
  const Eigen::Vector3d translation(2 * uniform(*rng), 2 * uniform(*rng),
                                    2 * uniform(*rng));
  const Rigid3d world_from_cam = Rigid3d(rotation, translation).Inverse();
  scene.cam_from_world =
      Rigid3d(rotation, Eigen::Vector3d(translation.x(), translation.y(), 0));
  if (options.planar) {
    // A plane facing the camera within ~45 degrees, 6 m ahead.
    const Eigen::Vector3d normal_in_cam =
        Eigen::Vector3d(0.6 * uniform(*rng), 0.6 * uniform(*rng), 1)
            .normalized();
    scene.plane_normal = world_from_cam.rotation * normal_in_cam;
    scene.plane_offset =
        scene.plane_normal.dot(world_from_cam * Eigen::Vector3d(0, 0, 6));
  }
  while (static_cast<int>(scene.points3D.size()) < options.num_points) {
    Eigen::Vector3d point_in_cam;
    if (options.planar) {
      Eigen::Vector3d point3D =
          world_from_cam * Eigen::Vector3d(0, 0, 6) +
          Eigen::Vector3d(8 * uniform(*rng), 8 * uniform(*rng),
                          8 * uniform(*rng));
      point3D -= scene.plane_normal *
                 (scene.plane_normal.dot(point3D) - scene.plane_offset -
                  options.planar_thickness * uniform(*rng));
      point_in_cam = Rigid3d(rotation, translation) * point3D;
    } else {
      const double theta =
          colmap::DegToRad(2 + 58 * (0.5 + 0.5 * uniform(*rng)));
      const double phi = M_PI * uniform(*rng);
      point_in_cam =
          (6 + 4 * uniform(*rng)) *
          Eigen::Vector3d(std::sin(theta) * std::cos(phi),
                          std::sin(theta) * std::sin(phi), std::cos(theta));
    }
    const double distance = point_in_cam.norm();
    const double radial_norm = point_in_cam.head<2>().norm();
    const double theta = std::atan2(radial_norm, point_in_cam.z());
    if (distance < 2 || distance > 10 || theta < colmap::DegToRad(2.0) ||
        theta > colmap::DegToRad(60.0)) {
      continue;
    }
    const Eigen::Vector2d direction = point_in_cam.head<2>() / radial_norm;
    Eigen::Vector2d point2D =
        testing::ProjectEquidistant(point_in_cam, kFocalPx);
    const bool is_inlier = 0.5 + 0.5 * uniform(*rng) >= options.outlier_ratio;
    if (is_inlier) {
      point2D += options.noise_px * Eigen::Vector2d(normal(*rng), normal(*rng));
    } else {
      do {
        point2D = Eigen::Vector2d(550 * uniform(*rng), 550 * uniform(*rng));
      } while (point2D.dot(direction) > 0 &&
               std::abs(point2D.x() * direction.y() -
                        point2D.y() * direction.x()) < 30);
    }
    scene.points2D.push_back(point2D);
    scene.points3D.push_back(world_from_cam * point_in_cam);
    scene.is_inlier.push_back(is_inlier);
  }
  return scene;
}

double RotationErrorDeg(const Rigid3d& a, const Rigid3d& b) {
  return RotationDifferenceDeg(a.rotation, b.rotation);
}

double TranslationError(const Rigid3d& a, const Rigid3d& b) {
  return (a.translation.head<2>() - b.translation.head<2>()).norm();
}

// The truth, or for planar scenes whichever of truth and mirror is closer
// to `estimate` (a radial camera cannot tell them apart on a plane).
Rigid3d ClosestTruth(const Scene& scene, const Rigid3d& estimate) {
  if (scene.plane_normal.isZero()) return scene.cam_from_world;
  const Rigid3d mirror = testing::MirrorThroughPlane(
      scene.cam_from_world, scene.plane_normal, scene.plane_offset);
  return RotationErrorDeg(estimate, mirror) <
                 RotationErrorDeg(estimate, scene.cam_from_world)
             ? mirror
             : scene.cam_from_world;
}

TEST(RadialPoseEstimator, ResidualsAreSquaredRadialErrors) {
  std::mt19937 rng(1);
  SceneOptions options = NoisyScene(200, 2, 0.3);
  Scene scene = MakeScene(options, &rng);
  // Two points on the wrong half-line and one on the optical axis.
  scene.points2D[0] = -scene.points2D[0];
  scene.points2D[1] = -scene.points2D[1];
  scene.points3D[2] = scene.cam_from_world.Inverse() * Eigen::Vector3d(0, 0, 4);
  std::vector<double> residuals;
  RadialPoseEstimator::Residuals(scene.points2D, scene.points3D,
                                 scene.cam_from_world, &residuals);
  ASSERT_EQ(residuals.size(), scene.points2D.size());
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(residuals[i], std::numeric_limits<double>::max());
  }
  int num_finite = 0;
  for (size_t i = 3; i < residuals.size(); ++i) {
    const double error = RadialReprojectionError(
        scene.cam_from_world, scene.points2D[i], scene.points3D[i]);
    if (std::isfinite(error)) {
      ++num_finite;
      EXPECT_NEAR(residuals[i], error * error, 1e-9 * (1 + error * error));
    } else {
      // Outliers that landed on the opposite half-line.
      EXPECT_EQ(residuals[i], std::numeric_limits<double>::max());
    }
  }
  EXPECT_GT(num_finite, 150);
  std::vector<double> local_residuals;
  RadialPoseLocalEstimator::Residuals(scene.points2D, scene.points3D,
                                      scene.cam_from_world, &local_residuals);
  EXPECT_EQ(local_residuals, residuals);
}

TEST(RadialPoseEstimator, MinimalEstimatorRecoversExactPose) {
  std::mt19937 rng(2);
  SceneOptions options;
  options.num_points = 5;
  for (int k = 0; k < 50; ++k) {
    const Scene scene = MakeScene(options, &rng);
    const std::vector<Rigid3d> models =
        RadialPoseEstimator::Estimate(scene.points2D, scene.points3D);
    double best = std::numeric_limits<double>::infinity();
    for (const Rigid3d& model : models) {
      best = std::min(best, RotationErrorDeg(model, scene.cam_from_world) +
                                TranslationError(model, scene.cam_from_world));
    }
    EXPECT_LT(best, 1e-7);
  }
}

// Exact data: the linear initialization plus LM reaches the truth, also for
// exactly planar scenes, where the linear system has a 3D null space.
TEST(RadialPoseLocalEstimator, RecoversExactPose) {
  std::mt19937 rng(3);
  for (const bool planar : {false, true}) {
    SceneOptions options;
    options.num_points = 50;
    options.planar = planar;
    options.planar_thickness = 0;
    for (int k = 0; k < 20; ++k) {
      const Scene scene = MakeScene(options, &rng);
      RadialPoseLocalEstimator estimator;
      const std::vector<Rigid3d> models =
          estimator.Estimate(scene.points2D, scene.points3D);
      ASSERT_EQ(models.size(), 1);
      const Rigid3d truth = ClosestTruth(scene, models[0]);
      EXPECT_LT(RotationErrorDeg(models[0], truth), 1e-8) << planar;
      EXPECT_LT(TranslationError(models[0], truth), 1e-8) << planar;
      EXPECT_EQ(models[0].translation.z(), 0);
    }
  }
}

TEST(RadialPoseLocalEstimator, RobustToNoiseAndFewOutliers) {
  std::mt19937 rng(4);
  SceneOptions options = NoisyScene(200, 1, 0.05);
  for (int k = 0; k < 10; ++k) {
    const Scene scene = MakeScene(options, &rng);
    RadialPoseLocalEstimator estimator;
    const std::vector<Rigid3d> models =
        estimator.Estimate(scene.points2D, scene.points3D);
    ASSERT_EQ(models.size(), 1);
    EXPECT_LT(RotationErrorDeg(models[0], scene.cam_from_world), 0.2);
    EXPECT_LT(TranslationError(models[0], scene.cam_from_world), 0.05);
  }
}

TEST(RadialPoseLocalEstimator, TooFewOrDegeneratePoints) {
  std::mt19937 rng(5);
  SceneOptions options;
  options.num_points = 5;
  Scene scene = MakeScene(options, &rng);
  RadialPoseLocalEstimator estimator;
  EXPECT_TRUE(estimator.Estimate(scene.points2D, scene.points3D).empty());
  options.num_points = 20;
  scene = MakeScene(options, &rng);
  for (Eigen::Vector3d& X : scene.points3D) X = scene.points3D[0];
  EXPECT_TRUE(estimator.Estimate(scene.points2D, scene.points3D).empty());
}

struct RobustResult {
  double max_rotation_error_deg = 0;
  double max_translation_error = 0;
  // Distance to the optimum of the refinement cost started from the truth
  // on the true inliers: what the estimator should find.
  double max_rotation_to_optimum_deg = 0;
  double max_translation_to_optimum = 0;
  double min_recall = 1;
  double min_precision = 1;
};

RobustResult RunRobustEstimation(const SceneOptions& scene_options,
                                 int num_scenes, unsigned seed) {
  std::mt19937 rng(seed);
  colmap::SetPRNGSeed(seed);
  RobustResult result;
  for (int k = 0; k < num_scenes; ++k) {
    const Scene scene = MakeScene(scene_options, &rng);
    RadialPoseEstimate estimate;
    EXPECT_TRUE(EstimateRadialPose(RadialPoseEstimationOptions(),
                                   scene.points2D, scene.points3D, &estimate));
    const Rigid3d truth = ClosestTruth(scene, estimate.cam_from_world);
    Rigid3d optimum = truth;
    EXPECT_TRUE(RefineRadialPose(RadialPoseEstimationOptions(), scene.points2D,
                                 scene.points3D, scene.is_inlier, &optimum));
    const Rigid3d& pose = estimate.cam_from_world;
    result.max_rotation_error_deg =
        std::max(result.max_rotation_error_deg, RotationErrorDeg(pose, truth));
    result.max_translation_error =
        std::max(result.max_translation_error, TranslationError(pose, truth));
    result.max_rotation_to_optimum_deg = std::max(
        result.max_rotation_to_optimum_deg, RotationErrorDeg(pose, optimum));
    result.max_translation_to_optimum = std::max(
        result.max_translation_to_optimum, TranslationError(pose, optimum));
    EXPECT_EQ(pose.translation.z(), 0);
    int true_positives = 0, num_true_inliers = 0;
    for (size_t i = 0; i < scene.points2D.size(); ++i) {
      num_true_inliers += scene.is_inlier[i];
      true_positives += scene.is_inlier[i] && estimate.inlier_mask[i];
    }
    EXPECT_EQ(estimate.inlier_mask.size(), scene.points2D.size());
    EXPECT_EQ(
        std::count(estimate.inlier_mask.begin(), estimate.inlier_mask.end(), 1),
        estimate.num_inliers);
    result.min_recall =
        std::min(result.min_recall,
                 true_positives / static_cast<double>(num_true_inliers));
    result.min_precision =
        std::min(result.min_precision,
                 true_positives / static_cast<double>(estimate.num_inliers));
    // 0.5 px noise per coordinate: the radial error (one component) has an
    // RMS of ~0.5 px.
    EXPECT_GT(estimate.radial_rms_px, 0.3);
    EXPECT_LT(estimate.radial_rms_px, 0.8);
  }
  std::printf(
      "rotation error %.4f deg, (tx, ty) error %.4f m; to the optimum "
      "%.1e deg, %.1e m; recall %.3f, precision %.3f\n",
      result.max_rotation_error_deg, result.max_translation_error,
      result.max_rotation_to_optimum_deg, result.max_translation_to_optimum,
      result.min_recall, result.min_precision);
  return result;
}

// The estimate is within the given distance of the truth, reaches the optimum
// of the refinement cost (1e-3 degrees, 0.1 mm: what the estimator should
// find, however far that is from the truth) and separates inliers from
// outliers (recall and precision > 95%).
void ExpectAccurate(const RobustResult& result, double max_rotation_error_deg,
                    double max_translation_error) {
  EXPECT_LT(result.max_rotation_error_deg, max_rotation_error_deg);
  EXPECT_LT(result.max_translation_error, max_translation_error);
  EXPECT_LT(result.max_rotation_to_optimum_deg, 1e-3);
  EXPECT_LT(result.max_translation_to_optimum, 1e-4);
  EXPECT_GT(result.min_recall, 0.95);
  EXPECT_GT(result.min_precision, 0.95);
}

// 300 points, 0.5 px noise, 30% outliers, over 20 random scenes.
TEST(EstimateRadialPose, NoiseAndOutliers) {
  SceneOptions options = NoisyScene(300, 0.5, 0.3);
  ExpectAccurate(RunRobustEstimation(options, 20, 6), 0.05, 0.01);
}

// Points within +-1e-3 m of a plane. A plane is much weaker for a radial
// camera than a 3D scene: the tilt of the camera relative to the plane is
// poorly constrained, the more so the closer the plane is to fronto-parallel
// (measured here: 0.01-0.1 degrees at 20-40 degrees of tilt, 0.3 degrees at
// 4 degrees), and the mirror pose fits as well (ClosestTruth). So the
// estimate is checked against the optimum of the cost, with a loose bound
// to the truth.
TEST(EstimateRadialPose, NearPlanarNoiseAndOutliers) {
  SceneOptions options = NoisyScene(300, 0.5, 0.3);
  options.planar = true;
  ExpectAccurate(RunRobustEstimation(options, 20, 7), 0.5, 0.06);
}

// RANSAC stops at the trial count the confidence asks for at the found
// inlier ratio w, log(1 - confidence) / log(1 - w^5), times
// dyn_num_trials_multiplier (1 by default; COLMAP's 3 triples it). More
// when the best model so far had fewer inliers than the final one.
TEST(EstimateRadialPose, TrialsFollowTheConfidenceBound) {
  std::mt19937 rng(11);
  colmap::SetPRNGSeed(11);
  for (int k = 0; k < 5; ++k) {
    const Scene scene = MakeScene(NoisyScene(300, 0.5, 0.3), &rng);
    for (const double multiplier : {1.0, 3.0}) {
      RadialPoseEstimationOptions options;
      options.dyn_num_trials_multiplier = multiplier;
      RadialPoseEstimate estimate;
      ASSERT_TRUE(EstimateRadialPose(options, scene.points2D, scene.points3D,
                                     &estimate));
      const double inlier_ratio =
          static_cast<double>(estimate.num_inliers) / scene.points2D.size();
      const double bound = std::log(1 - options.confidence) /
                           std::log(1 - std::pow(inlier_ratio, 5));
      EXPECT_GE(estimate.num_trials, options.min_num_trials);
      EXPECT_LT(estimate.num_trials, 1.5 * multiplier * bound + 2)
          << multiplier;
      EXPECT_GT(estimate.num_trials, 0.9 * multiplier * bound - 2)
          << multiplier;
      EXPECT_LT(RotationErrorDeg(estimate.cam_from_world, scene.cam_from_world),
                0.05);
    }
  }
}

TEST(EstimateRadialPose, ExactDataWithOutliers) {
  std::mt19937 rng(8);
  colmap::SetPRNGSeed(8);
  SceneOptions options;
  options.num_points = 100;
  options.outlier_ratio = 0.3;
  for (int k = 0; k < 5; ++k) {
    const Scene scene = MakeScene(options, &rng);
    RadialPoseEstimate estimate;
    ASSERT_TRUE(EstimateRadialPose(RadialPoseEstimationOptions(),
                                   scene.points2D, scene.points3D, &estimate));
    EXPECT_LT(RotationErrorDeg(estimate.cam_from_world, scene.cam_from_world),
              1e-8);
    EXPECT_LT(TranslationError(estimate.cam_from_world, scene.cam_from_world),
              1e-8);
    EXPECT_LT(estimate.radial_rms_px, 1e-6);
    for (size_t i = 0; i < scene.points2D.size(); ++i) {
      EXPECT_EQ(estimate.inlier_mask[i], scene.is_inlier[i]) << i;
    }
  }
}

TEST(EstimateRadialPose, FailsOnTooFewPointsOrInliers) {
  std::mt19937 rng(9);
  colmap::SetPRNGSeed(9);
  SceneOptions options;
  options.num_points = 11;
  Scene scene = MakeScene(options, &rng);
  RadialPoseEstimate estimate;
  const RadialPoseEstimationOptions estimation_options;
  // 11 < min_num_inliers = 12.
  EXPECT_FALSE(EstimateRadialPose(estimation_options, scene.points2D,
                                  scene.points3D, &estimate));
  RadialPoseEstimationOptions permissive = estimation_options;
  permissive.min_num_inliers = 0;
  scene.points2D.resize(4);
  scene.points3D.resize(4);
  EXPECT_FALSE(EstimateRadialPose(permissive, scene.points2D, scene.points3D,
                                  &estimate));
  // Enough points, but only ~5 inliers among 100.
  options.num_points = 100;
  options.outlier_ratio = 0.95;
  scene = MakeScene(options, &rng);
  const int num_inliers =
      std::count(scene.is_inlier.begin(), scene.is_inlier.end(), 1);
  ASSERT_LT(num_inliers, 12);
  EXPECT_FALSE(EstimateRadialPose(estimation_options, scene.points2D,
                                  scene.points3D, &estimate));
  // Mismatched sizes and invalid options.
  scene.points3D.pop_back();
  EXPECT_FALSE(EstimateRadialPose(estimation_options, scene.points2D,
                                  scene.points3D, &estimate));
  scene.points2D.pop_back();
  RadialPoseEstimationOptions invalid = estimation_options;
  invalid.max_error_px = 0;
  EXPECT_FALSE(
      EstimateRadialPose(invalid, scene.points2D, scene.points3D, &estimate));
}

TEST(EstimateRadialPose, DegenerateInputNeverCrashesOrGivesNaN) {
  std::mt19937 rng(10);
  colmap::SetPRNGSeed(10);
  SceneOptions options;
  options.num_points = 60;
  const Scene scene = MakeScene(options, &rng);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<Scene> degenerate(4, scene);
  for (Eigen::Vector3d& X : degenerate[0].points3D) X = scene.points3D[0];
  for (Eigen::Vector2d& x : degenerate[1].points2D) x.setZero();
  for (Eigen::Vector2d& x : degenerate[2].points2D) x = Eigen::Vector2d(nan, 1);
  for (int i = 0; i < 60; ++i) {
    degenerate[3].points3D[i] =
        scene.points3D[0] + i * (scene.points3D[1] - scene.points3D[0]);
  }
  for (size_t k = 0; k < degenerate.size(); ++k) {
    RadialPoseEstimate estimate;
    if (EstimateRadialPose(RadialPoseEstimationOptions(),
                           degenerate[k].points2D, degenerate[k].points3D,
                           &estimate)) {
      EXPECT_TRUE(estimate.cam_from_world.rotation.coeffs().allFinite()) << k;
      EXPECT_TRUE(estimate.cam_from_world.translation.allFinite()) << k;
      EXPECT_TRUE(std::isfinite(estimate.radial_rms_px)) << k;
    }
    // All points identical, at the principal point or NaN: nothing fits.
    if (k < 3) {
      EXPECT_EQ(estimate.num_inliers, 0) << k;
    }
  }
  // A few non-finite correspondences among good ones are outliers.
  Scene mixed = scene;
  mixed.points2D[3] = Eigen::Vector2d(nan, 1);
  mixed.points3D[7].z() = std::numeric_limits<double>::infinity();
  RadialPoseEstimate estimate;
  ASSERT_TRUE(EstimateRadialPose(RadialPoseEstimationOptions(), mixed.points2D,
                                 mixed.points3D, &estimate));
  EXPECT_FALSE(estimate.inlier_mask[3]);
  EXPECT_FALSE(estimate.inlier_mask[7]);
  EXPECT_EQ(estimate.num_inliers, 58);
  EXPECT_LT(RotationErrorDeg(estimate.cam_from_world, scene.cam_from_world),
            1e-8);
}

TEST(RefineRadialPose, ConvergesFromPerturbedPoseAndKeepsTz) {
  std::mt19937 rng(11);
  SceneOptions options;
  options.num_points = 100;
  const Scene scene = MakeScene(options, &rng);
  const std::vector<char> all_inliers(scene.points2D.size(), 1);
  const RadialPoseEstimationOptions refine_options;
  for (const double tz : {0.0, 1.5}) {
    Rigid3d pose(
        Eigen::AngleAxisd(colmap::DegToRad(2.0),
                          Eigen::Vector3d(1, 2, 3).normalized()) *
            scene.cam_from_world.rotation,
        scene.cam_from_world.translation + Eigen::Vector3d(0.2, -0.1, tz));
    ASSERT_TRUE(RefineRadialPose(refine_options, scene.points2D, scene.points3D,
                                 all_inliers, &pose));
    EXPECT_LT(RotationErrorDeg(pose, scene.cam_from_world), 1e-8);
    EXPECT_LT(TranslationError(pose, scene.cam_from_world), 1e-8);
    EXPECT_EQ(pose.translation.z(), tz);
  }
  // Fewer than 5 inliers, mismatched mask.
  std::vector<char> four(scene.points2D.size(), 0);
  std::fill(four.begin(), four.begin() + 4, 1);
  Rigid3d pose = scene.cam_from_world;
  EXPECT_FALSE(RefineRadialPose(refine_options, scene.points2D, scene.points3D,
                                four, &pose));
  EXPECT_FALSE(RefineRadialPose(refine_options, scene.points2D, scene.points3D,
                                std::vector<char>(3, 1), &pose));
}

// RefineRadialPose minimizes the cost of a Ceres problem made of
// RadialReprojectionCost blocks with a Cauchy loss: both reach the same
// optimum on noisy data.
TEST(RefineRadialPose, AgreesWithCeresOnRadialReprojectionCost) {
  std::mt19937 rng(14);
  SceneOptions options = NoisyScene(300, 1, 0.1);
  for (int k = 0; k < 3; ++k) {
    const Scene scene = MakeScene(options, &rng);
    const std::vector<char> all(scene.points2D.size(), 1);
    RadialPoseEstimationOptions refine_options;
    refine_options.loss_scale_px = 2;
    const Rigid3d start(
        Eigen::AngleAxisd(colmap::DegToRad(1.0), Eigen::Vector3d::UnitX()) *
            scene.cam_from_world.rotation,
        scene.cam_from_world.translation + Eigen::Vector3d(0.1, 0.1, 0));
    Rigid3d refined = start;
    ASSERT_TRUE(RefineRadialPose(refine_options, scene.points2D, scene.points3D,
                                 all, &refined));

    double rotation[4] = {start.rotation.w(), start.rotation.x(),
                          start.rotation.y(), start.rotation.z()};
    double translation[3] = {start.translation.x(), start.translation.y(), 0};
    ceres::Problem problem;
    for (size_t i = 0; i < scene.points2D.size(); ++i) {
      problem.AddResidualBlock(
          RadialReprojectionCost::Create(scene.points2D[i], scene.points3D[i]),
          new ceres::CauchyLoss(refine_options.loss_scale_px), rotation,
          translation);
    }
    problem.SetManifold(rotation, new ceres::QuaternionManifold);
    problem.SetManifold(translation, new ceres::SubsetManifold(3, {2}));
    ceres::Solver::Options solver_options;
    solver_options.linear_solver_type = ceres::DENSE_QR;
    solver_options.function_tolerance = 1e-14;
    solver_options.gradient_tolerance = 1e-16;
    solver_options.parameter_tolerance = 1e-14;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
    ASSERT_TRUE(summary.IsSolutionUsable());
    const Rigid3d ceres_refined(
        Eigen::Quaterniond(rotation[0], rotation[1], rotation[2], rotation[3]),
        Eigen::Vector3d(translation[0], translation[1], 0));
    EXPECT_GT(RotationErrorDeg(start, ceres_refined), 0.5);
    EXPECT_LT(RotationErrorDeg(refined, ceres_refined), 1e-7);
    EXPECT_LT(TranslationError(refined, ceres_refined), 1e-8);
  }
}

// Measures the time per EstimateRadialPose (30% outliers, 0.5 px noise) and
// checks its accuracy on the way.
TEST(EstimateRadialPose, Timing) {
  for (const int num_points : {300, 2000}) {
    std::mt19937 rng(13);
    colmap::SetPRNGSeed(13);
    SceneOptions options;
    options.num_points = num_points;
    options.noise_px = 0.5;
    options.outlier_ratio = 0.3;
    constexpr int kNumRuns = 10;
    double total_seconds = 0;
    double total_cpu_seconds = 0;
    int total_trials = 0;
    for (int k = 0; k < kNumRuns; ++k) {
      const Scene scene = MakeScene(options, &rng);
      RadialPoseEstimate estimate;
      const auto start = std::chrono::steady_clock::now();
      const std::clock_t cpu_start = std::clock();
      ASSERT_TRUE(EstimateRadialPose(RadialPoseEstimationOptions(),
                                     scene.points2D, scene.points3D,
                                     &estimate));
      total_cpu_seconds +=
          static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
      total_seconds += std::chrono::duration<double>(
                           std::chrono::steady_clock::now() - start)
                           .count();
      total_trials += estimate.num_trials;
      EXPECT_LT(RotationErrorDeg(estimate.cam_from_world, scene.cam_from_world),
                0.05);
    }
    std::printf(
        "%d correspondences: %.2f ms (CPU %.2f ms) per "
        "EstimateRadialPose, %.0f trials\n",
        num_points, 1e3 * total_seconds / kNumRuns,
        1e3 * total_cpu_seconds / kNumRuns,
        total_trials / static_cast<double>(kNumRuns));
    RecordProperty("ms_per_estimate_" + std::to_string(num_points),
                   std::to_string(1e3 * total_seconds / kNumRuns));
  }
}

}  // namespace radial_pose_estimator_test
}  // namespace rig_calibrator
