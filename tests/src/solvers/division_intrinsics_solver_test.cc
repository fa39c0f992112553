#include "src/solvers/division_intrinsics_solver.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace rig_calibrator {
namespace division_intrinsics_solver_test {

// Data from the division model itself: pick the distorted pixel, undistort
// it, and place the 3D point on the undistorted ray at depth 2-10. Minimal
// and overdetermined sets give the truth; the distortion terms are checked
// relative to their size, so a solver that drops the pixel scaling fails.
TEST(SolveDivisionIntrinsics, MinimalAndOverdeterminedExactData) {
  const double focal = 450, tz = -0.8, kappa1 = -4e-7, kappa2 = 2e-13;
  std::mt19937 generator(3);
  std::uniform_real_distribution<double> uniform(-300, 300);
  for (int num_kappa = 0; num_kappa <= 2; ++num_kappa) {
    SCOPED_TRACE(num_kappa);
    for (const int num_points : {num_kappa + 2, 50}) {
      std::vector<Eigen::Vector2d> x;
      std::vector<Eigen::Vector3d> points_cam;
      const double k1 = num_kappa > 0 ? kappa1 : 0;
      const double k2 = num_kappa > 1 ? kappa2 : 0;
      for (int i = 0; i < num_points; ++i) {
        const Eigen::Vector2d pixel(uniform(generator), uniform(generator));
        const double rho2 = pixel.squaredNorm();
        const Eigen::Vector2d undistorted =
            pixel / (1 + k1 * rho2 + k2 * rho2 * rho2);
        const double depth = 2 + (uniform(generator) + 300) / 75;
        x.push_back(pixel);
        points_cam.emplace_back(depth * undistorted.x() / focal,
                                depth * undistorted.y() / focal, depth - tz);
      }
      DivisionIntrinsics model;
      ASSERT_TRUE(SolveDivisionIntrinsics(x, points_cam, num_kappa, &model));
      EXPECT_EQ(model.num_kappa, num_kappa);
      EXPECT_NEAR(model.focal, focal, 1e-9 * focal);
      EXPECT_NEAR(model.tz, tz, 1e-9);
      EXPECT_NEAR(model.kappa[0], k1, 1e-9 * 4e-7);
      EXPECT_NEAR(model.kappa[1], k2, 1e-9 * 2e-13);
    }
  }
}

// 0.5 px noise on 200 points: the least-squares estimate stays close.
TEST(SolveDivisionIntrinsics, NoisyData) {
  const double focal = 450, tz = 0.3, kappa1 = -4e-7;
  std::mt19937 generator(4);
  std::uniform_real_distribution<double> uniform(-300, 300);
  std::normal_distribution<double> noise(0, 0.5);
  std::vector<Eigen::Vector2d> x;
  std::vector<Eigen::Vector3d> points_cam;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector2d pixel(uniform(generator), uniform(generator));
    const Eigen::Vector2d undistorted =
        pixel / (1 + kappa1 * pixel.squaredNorm());
    const double depth = 2 + (uniform(generator) + 300) / 75;
    x.push_back(pixel + Eigen::Vector2d(noise(generator), noise(generator)));
    points_cam.emplace_back(depth * undistorted.x() / focal,
                            depth * undistorted.y() / focal, depth - tz);
  }
  DivisionIntrinsics model;
  ASSERT_TRUE(SolveDivisionIntrinsics(x, points_cam, 1, &model));
  EXPECT_NEAR(model.focal, focal, 0.005 * focal);
  EXPECT_NEAR(model.tz, tz, 0.02);
  EXPECT_NEAR(model.kappa[0], kappa1, 0.05 * 4e-7);
}

TEST(SolveDivisionIntrinsics, RejectsBadInput) {
  DivisionIntrinsics model;
  const std::vector<Eigen::Vector2d> x = {Eigen::Vector2d(10, 0),
                                          Eigen::Vector2d(20, 0)};
  // Too few points for two unknowns plus one distortion term.
  EXPECT_FALSE(SolveDivisionIntrinsics(
      x, {Eigen::Vector3d(0.1, 0, 5), Eigen::Vector3d(0.2, 0, 5)}, 1, &model));
  // Points on the wrong half-line need f < 0.
  EXPECT_FALSE(SolveDivisionIntrinsics(
      x, {Eigen::Vector3d(-0.1, 0, 5), Eigen::Vector3d(-0.4, 0, 7)}, 0,
      &model));
  // All pixels on the principal point: no radial information.
  EXPECT_FALSE(SolveDivisionIntrinsics(
      {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()},
      {Eigen::Vector3d(0.1, 0, 5), Eigen::Vector3d(0.2, 0, 5)}, 0, &model));
  // More than two terms.
  EXPECT_FALSE(SolveDivisionIntrinsics(
      {x[0], x[1], x[0], x[1], x[0]},
      std::vector<Eigen::Vector3d>(5, Eigen::Vector3d(0.1, 0, 5)), 3, &model));
}

}  // namespace division_intrinsics_solver_test
}  // namespace rig_calibrator
