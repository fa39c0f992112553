#include "src/solvers/radial_pose_solver.h"

#include <colmap/util/math.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "src/geometry/radial_error.h"
#include "tests/src/solvers/radial_pose_test_scene.h"

namespace rig_calibrator {
namespace radial_pose_solver_test {

enum class SceneKind { kGeneral, kNearPlanar, kPlanar };

struct Scene {
  Rigid3d cam_from_world;
  std::vector<Eigen::Vector2d> points2D;
  std::vector<Eigen::Vector3d> points3D;
  // Plane n.X = d of planar scenes.
  Eigen::Vector3d plane_normal = Eigen::Vector3d::Zero();
  double plane_offset = 0;
};

using testing::MirrorThroughPlane;
using testing::RandomRotation;

constexpr double kFocalPx = 500;

// A random camera and `num_points` points 2-10 m away, up to 100 degrees off
// the optical axis (in front of and beside the camera). Planar scenes put the
// points on a random plane through a point in front of the camera; near-planar
// ones add +-1e-3 m along its normal.
Scene MakeScene(SceneKind kind, int num_points, std::mt19937* rng) {
  std::uniform_real_distribution<double> uniform(-1, 1);
  Scene scene;
  const Eigen::Quaterniond rotation = RandomRotation(rng);
  const Eigen::Vector3d translation(2 * uniform(*rng), 2 * uniform(*rng),
                                    2 * uniform(*rng));
  scene.cam_from_world = Rigid3d(rotation, translation);
  const Rigid3d world_from_cam = scene.cam_from_world.Inverse();

  if (kind != SceneKind::kGeneral) {
    scene.plane_normal = RandomRotation(rng) * Eigen::Vector3d::UnitZ();
    // Keep the plane at least 45 degrees from containing the optical axis.
    const Eigen::Vector3d axis_in_world =
        world_from_cam.rotation * Eigen::Vector3d::UnitZ();
    if (std::abs(scene.plane_normal.dot(axis_in_world)) < 0.7) {
      scene.plane_normal =
          (scene.plane_normal + 2 * axis_in_world).normalized();
    }
    scene.plane_offset =
        scene.plane_normal.dot(world_from_cam * Eigen::Vector3d(0, 0, 5));
  }
  while (static_cast<int>(scene.points3D.size()) < num_points) {
    Eigen::Vector3d point_in_cam;
    if (kind == SceneKind::kGeneral) {
      const double theta =
          colmap::DegToRad(5 + 95 * (0.5 + 0.5 * uniform(*rng)));
      const double phi = M_PI * uniform(*rng);
      const double distance = 6 + 4 * uniform(*rng);
      point_in_cam = distance * Eigen::Vector3d(std::sin(theta) * std::cos(phi),
                                                std::sin(theta) * std::sin(phi),
                                                std::cos(theta));
    } else {
      // A point of the plane around its intersection with the optical axis.
      const Eigen::Vector3d center = world_from_cam * Eigen::Vector3d(0, 0, 5);
      Eigen::Vector3d offset(4 * uniform(*rng), 4 * uniform(*rng),
                             4 * uniform(*rng));
      offset -= scene.plane_normal * scene.plane_normal.dot(offset);
      Eigen::Vector3d point3D = center + offset;
      if (kind == SceneKind::kNearPlanar) {
        point3D += 1e-3 * uniform(*rng) * scene.plane_normal;
      }
      point_in_cam = scene.cam_from_world * point3D;
      const double distance = point_in_cam.norm();
      const double off_axis =
          std::atan2(point_in_cam.head<2>().norm(), point_in_cam.z());
      if (distance < 2 || distance > 10 || off_axis < colmap::DegToRad(5.0) ||
          off_axis > colmap::DegToRad(100.0)) {
        continue;
      }
    }
    scene.points2D.push_back(
        testing::ProjectEquidistant(point_in_cam, kFocalPx));
    scene.points3D.push_back(world_from_cam * point_in_cam);
  }
  return scene;
}

// Error of a radial pose against the truth: max of the rotation error
// (radians) and the error of (tx, ty) (meters; the scene is ~1-10 m).
double PoseError(const Rigid3d& estimate, const Rigid3d& truth) {
  const double rotation_error =
      RotationDifferenceRad(estimate.rotation, truth.rotation);
  const double translation_error =
      (estimate.translation.head<2>() - truth.translation.head<2>()).norm();
  return std::max(rotation_error, translation_error);
}

// Best error over the solutions; checks that every solution is finite, has
// tz == 0 and puts every sample point on its half-line (error ~0).
double BestSolutionError(const Scene& scene,
                         const std::vector<Rigid3d>& solutions) {
  double best = std::numeric_limits<double>::infinity();
  for (const Rigid3d& solution : solutions) {
    EXPECT_TRUE(solution.rotation.coeffs().allFinite());
    EXPECT_TRUE(solution.translation.allFinite());
    EXPECT_EQ(solution.translation.z(), 0);
    for (size_t i = 0; i < scene.points2D.size(); ++i) {
      EXPECT_LT(RadialReprojectionError(solution, scene.points2D[i],
                                        scene.points3D[i]),
                1e-6);
    }
    best = std::min(best, PoseError(solution, scene.cam_from_world));
  }
  return best;
}

struct Accuracy {
  double median;
  double worst;
};

// Solves `num_instances` random 5-point instances; the accuracy is that of
// the solution closest to the truth. For exact planes the mirrored pose fits
// the points as well, so it must be among the solutions too.
Accuracy SolveRandomInstances(SceneKind kind, int num_instances,
                              unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<double> errors;
  for (int k = 0; k < num_instances; ++k) {
    const Scene scene = MakeScene(kind, 5, &rng);
    std::vector<Rigid3d> solutions;
    SolveRadialPose5(scene.points2D, scene.points3D, &solutions);
    EXPECT_LE(solutions.size(), 4);
    errors.push_back(BestSolutionError(scene, solutions));
    if (kind == SceneKind::kPlanar) {
      Scene mirrored = scene;
      mirrored.cam_from_world = MirrorThroughPlane(
          scene.cam_from_world, scene.plane_normal, scene.plane_offset);
      EXPECT_GT(PoseError(mirrored.cam_from_world, scene.cam_from_world), 1e-3);
      EXPECT_LT(BestSolutionError(mirrored, solutions), 1e-6);
    }
  }
  std::sort(errors.begin(), errors.end());
  return {errors[errors.size() / 2], errors.back()};
}

TEST(RadialPoseSolver, RecoversGeneralScenes) {
  const Accuracy accuracy = SolveRandomInstances(SceneKind::kGeneral, 2000, 1);
  EXPECT_LT(accuracy.median, 1e-12);
  EXPECT_LT(accuracy.worst, 1e-8);
}

TEST(RadialPoseSolver, RecoversNearPlanarScenes) {
  const Accuracy accuracy =
      SolveRandomInstances(SceneKind::kNearPlanar, 2000, 2);
  EXPECT_LT(accuracy.median, 1e-12);
  EXPECT_LT(accuracy.worst, 1e-8);
}

TEST(RadialPoseSolver, RecoversPlanarScenesAndTheirMirror) {
  const Accuracy accuracy = SolveRandomInstances(SceneKind::kPlanar, 2000, 3);
  EXPECT_LT(accuracy.median, 1e-12);
  EXPECT_LT(accuracy.worst, 1e-8);
}

// Noisy samples (0.5 px per coordinate, ~1e-3 rad at 500 px): every solution
// still fits its 5 points exactly (the solver is exact, the noise goes into
// the pose), and the closest one is near the truth, at an error that grows
// in proportion to the noise. Measured (rad or m): median 3.3e-3 at 0.1 px,
// 1.7e-2 at 0.5 px; a 90th percentile 7x higher (ill-conditioned samples).
TEST(RadialPoseSolver, NoisySamplesGiveNearbyPoses) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  for (const double noise_px : {0.1, 0.5}) {
    std::vector<double> errors;
    for (int k = 0; k < 500; ++k) {
      Scene scene = MakeScene(SceneKind::kGeneral, 5, &rng);
      for (Eigen::Vector2d& x : scene.points2D) {
        x += noise_px * Eigen::Vector2d(normal(rng), normal(rng));
      }
      std::vector<Rigid3d> solutions;
      SolveRadialPose5(scene.points2D, scene.points3D, &solutions);
      errors.push_back(BestSolutionError(scene, solutions));
    }
    std::sort(errors.begin(), errors.end());
    const double median = errors[errors.size() / 2];
    std::printf("noise %.1f px: median pose error %.1e, 90%% %.1e\n", noise_px,
                median, errors[errors.size() * 9 / 10]);
    EXPECT_GT(median, 0.015 * noise_px);
    EXPECT_LT(median, 0.06 * noise_px);
  }
}

// A sample with a wrong match (one point's 2D position replaced by a random
// pixel): the solutions fit the 5 given points, outlier included, so none is
// the true pose; this is what RANSAC relies on to reject the sample.
TEST(RadialPoseSolver, SampleWithAnOutlierFitsTheOutlier) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> uniform(-1, 1);
  int num_far = 0;
  for (int k = 0; k < 200; ++k) {
    Scene scene = MakeScene(SceneKind::kGeneral, 5, &rng);
    scene.points2D[k % 5] =
        Eigen::Vector2d(600 * uniform(rng), 600 * uniform(rng));
    std::vector<Rigid3d> solutions;
    SolveRadialPose5(scene.points2D, scene.points3D, &solutions);
    num_far += BestSolutionError(scene, solutions) > 1e-2;
  }
  EXPECT_GT(num_far, 190);
}

TEST(RadialPoseSolver, IgnoresTheScaleOfImagePoints) {
  std::mt19937 rng(4);
  for (int k = 0; k < 100; ++k) {
    Scene scene = MakeScene(SceneKind::kGeneral, 5, &rng);
    std::uniform_real_distribution<double> scale(1e-3, 1e3);
    for (Eigen::Vector2d& x : scene.points2D) x *= scale(rng);
    std::vector<Rigid3d> solutions;
    SolveRadialPose5(scene.points2D, scene.points3D, &solutions);
    EXPECT_LT(BestSolutionError(scene, solutions), 1e-8);
  }
}

TEST(RadialPoseSolver, DegenerateSamplesGiveNoInvalidPoses) {
  std::mt19937 rng(5);
  const Scene scene = MakeScene(SceneKind::kGeneral, 5, &rng);
  std::vector<Scene> degenerate(6, scene);
  // All 3D points equal.
  for (Eigen::Vector3d& X : degenerate[0].points3D) X = scene.points3D[0];
  // A 2D point at the principal point: no direction.
  degenerate[1].points2D[2].setZero();
  // NaN and infinite input.
  degenerate[2].points3D[1].x() = std::numeric_limits<double>::quiet_NaN();
  degenerate[3].points2D[4].y() = std::numeric_limits<double>::infinity();
  // Collinear 3D points.
  for (int i = 0; i < 5; ++i) {
    degenerate[4].points3D[i] =
        scene.points3D[0] + i * (scene.points3D[1] - scene.points3D[0]);
  }
  // Wrong sample size.
  degenerate[5].points2D.pop_back();
  degenerate[5].points3D.pop_back();
  for (size_t k = 0; k < degenerate.size(); ++k) {
    std::vector<Rigid3d> solutions;
    SolveRadialPose5(degenerate[k].points2D, degenerate[k].points3D,
                     &solutions);
    for (const Rigid3d& solution : solutions) {
      EXPECT_TRUE(solution.rotation.coeffs().allFinite()) << k;
      EXPECT_TRUE(solution.translation.allFinite()) << k;
    }
    // Collinear points may give poses (the line is consistent with many).
    if (k != 4) {
      EXPECT_TRUE(solutions.empty()) << k;
    }
  }
}

TEST(RadialPoseSolver, AppendsToExistingSolutions) {
  std::mt19937 rng(6);
  const Scene scene = MakeScene(SceneKind::kGeneral, 5, &rng);
  std::vector<Rigid3d> solutions(1);
  SolveRadialPose5(scene.points2D, scene.points3D, &solutions);
  ASSERT_GE(solutions.size(), 2);
  EXPECT_EQ(solutions[0].translation, Eigen::Vector3d::Zero());
}

}  // namespace radial_pose_solver_test
}  // namespace rig_calibrator
