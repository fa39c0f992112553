#include "src/solvers/radial_pose_solver.h"
#include "src/geometry/radial_error.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace rig_calibrator {
namespace {

enum class SceneKind { kGeneral, kNearPlanar, kPlanar };

struct Scene {
  Rigid3d cam_from_world;
  std::vector<Eigen::Vector2d> points2D;
  std::vector<Eigen::Vector3d> points3D;
  // Plane n.X = d of planar scenes.
  Eigen::Vector3d plane_normal = Eigen::Vector3d::Zero();
  double plane_offset = 0;
};

Eigen::Quaterniond RandomRotation(std::mt19937* rng) {
  std::normal_distribution<double> normal;
  return Eigen::Quaterniond(normal(*rng), normal(*rng), normal(*rng),
                            normal(*rng))
      .normalized();
}

// Equidistant fisheye with f = 500 px: the image radius is f theta for a ray
// at angle theta from the optical axis. Any radial function would do.
Eigen::Vector2d Project(const Eigen::Vector3d& point_in_cam) {
  const double radial_norm = point_in_cam.head<2>().norm();
  const double theta = std::atan2(radial_norm, point_in_cam.z());
  return 500.0 * theta * point_in_cam.head<2>() / radial_norm;
}

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
      const double theta = (5 + 95 * (0.5 + 0.5 * uniform(*rng))) * M_PI / 180;
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
      if (distance < 2 || distance > 10 || off_axis < 5 * M_PI / 180 ||
          off_axis > 100 * M_PI / 180) {
        continue;
      }
    }
    scene.points2D.push_back(Project(point_in_cam));
    scene.points3D.push_back(world_from_cam * point_in_cam);
  }
  return scene;
}

// Error of a radial pose against the truth: max of the rotation error
// (radians) and the error of (tx, ty) (meters; the scene is ~1-10 m).
double PoseError(const Rigid3d& estimate, const Rigid3d& truth) {
  const double rotation_error =
      RotationDifferenceDeg(estimate.rotation, truth.rotation) * M_PI / 180;
  const double translation_error =
      (estimate.translation.head<2>() - truth.translation.head<2>()).norm();
  return std::max(rotation_error, translation_error);
}

// The radial pose that fits every point of the plane n.X = d as well as
// `pose`: reflect the world through the plane, X' = X - 2 n (n.X - d), which
// fixes its points; the first two rows R S (S = I - 2 n n^T) and
// t12' = t12 + 2 d (R n)_12 then give a rotation with r3 = r1 x r2.
Rigid3d MirrorThroughPlane(const Rigid3d& pose, const Eigen::Vector3d& n,
                           double d) {
  const Eigen::Matrix3d reflection =
      Eigen::Matrix3d::Identity() - 2 * n * n.transpose();
  Eigen::Matrix3d rotation = pose.RotationMatrix() * reflection;
  rotation.row(2) = rotation.row(0).cross(rotation.row(1));
  Eigen::Vector3d translation =
      pose.translation + 2 * d * (pose.RotationMatrix() * n);
  translation.z() = 0;
  return Rigid3d(rotation, translation);
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

TEST(RadialReprojectionError, DistanceToTheHalfLine) {
  // Identity pose: the camera-frame point is X, its radial direction (1, 0)
  // for X = (2, 0, 5).
  const Rigid3d identity;
  const Eigen::Vector3d X(2, 0, 5);
  EXPECT_NEAR(RadialReprojectionError(identity, Eigen::Vector2d(100, 3), X), 3,
              1e-12);
  EXPECT_NEAR(RadialReprojectionError(identity, Eigen::Vector2d(100, -4), X), 4,
              1e-12);
  EXPECT_EQ(RadialReprojectionError(identity, Eigen::Vector2d(250, 0), X), 0);
  // The focal length and the depth do not matter, only the direction.
  EXPECT_NEAR(RadialReprojectionError(identity, Eigen::Vector2d(100, 3),
                                      Eigen::Vector3d(7, 0, -1)),
              3, 1e-12);
  // Opposite half-line, perpendicular direction, optical axis, NaN.
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(RadialReprojectionError(identity, Eigen::Vector2d(-100, 3), X),
            inf);
  EXPECT_EQ(RadialReprojectionError(identity, Eigen::Vector2d(0, 3), X), inf);
  EXPECT_EQ(RadialReprojectionError(identity, Eigen::Vector2d(100, 3),
                                    Eigen::Vector3d(0, 0, 5)),
            inf);
  EXPECT_EQ(
      RadialReprojectionError(
          identity,
          Eigen::Vector2d(std::numeric_limits<double>::quiet_NaN(), 3), X),
      inf);
  // A pose with translation: t moves the point to (2 + 1, -3 + 3) = (3, 0).
  const Rigid3d shifted(Eigen::Quaterniond::Identity(),
                        Eigen::Vector3d(1, 3, 0));
  EXPECT_NEAR(RadialReprojectionError(shifted, Eigen::Vector2d(100, 5),
                                      Eigen::Vector3d(2, -3, 5)),
              5, 1e-12);
}

}  // namespace
}  // namespace rig_calibrator
