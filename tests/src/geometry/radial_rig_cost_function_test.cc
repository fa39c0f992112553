#include "src/geometry/radial_rig_cost_function.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>
#include <gtest/gtest.h>

#include <array>
#include <random>
#include <string>

#include "src/geometry/radial_residual.h"

namespace rig_calibrator {
namespace {

// The same residual by automatic differentiation: the reference for the
// analytic Jacobians.
struct RadialRigResidual {
  Eigen::Vector2d point2D;
  Eigen::Vector3d point3D;

  template <typename T>
  bool operator()(const T* cam_from_rig, const T* rig_from_world,
                  const T* principal_point, T* residuals) const {
    const T point[3] = {T(point3D(0)), T(point3D(1)), T(point3D(2))};
    T point_in_rig[3];
    ceres::AngleAxisRotatePoint(rig_from_world, point, point_in_rig);
    for (int r = 0; r < 3; ++r) point_in_rig[r] += rig_from_world[3 + r];
    T point_in_cam[3];
    ceres::AngleAxisRotatePoint(cam_from_rig, point_in_rig, point_in_cam);
    for (int r = 0; r < 3; ++r) point_in_cam[r] += cam_from_rig[3 + r];
    const T centered[2] = {T(point2D(0)) - principal_point[0],
                           T(point2D(1)) - principal_point[1]};
    RadialResidual(centered, point_in_cam, residuals);
    return true;
  }
};

struct Evaluation {
  std::array<double, 2> residual;
  std::array<double, 12> jacobian_cam, jacobian_rig;
  std::array<double, 4> jacobian_principal_point;
};

Evaluation Evaluate(const ceres::CostFunction& cost,
                    const std::array<double, 6>& cam_from_rig,
                    const std::array<double, 6>& rig_from_world,
                    const std::array<double, 2>& principal_point) {
  Evaluation evaluation;
  const double* parameters[] = {cam_from_rig.data(), rig_from_world.data(),
                                principal_point.data()};
  double* jacobians[] = {evaluation.jacobian_cam.data(),
                         evaluation.jacobian_rig.data(),
                         evaluation.jacobian_principal_point.data()};
  EXPECT_TRUE(cost.Evaluate(parameters, evaluation.residual.data(), jacobians));
  return evaluation;
}

template <size_t N>
void ExpectNear(const std::array<double, N>& actual,
                const std::array<double, N>& expected, double tolerance,
                const std::string& what) {
  for (size_t k = 0; k < N; ++k) {
    EXPECT_NEAR(actual[k], expected[k], tolerance) << what << " [" << k << "]";
  }
}

// The camera-frame point of the cost function's chain, as RadialRigResidual
// computes it.
Eigen::Vector3d PointInCamera(const std::array<double, 6>& cam_from_rig,
                              const std::array<double, 6>& rig_from_world,
                              const Eigen::Vector3d& point3D) {
  double point_in_rig[3], point_in_cam[3];
  ceres::AngleAxisRotatePoint(rig_from_world.data(), point3D.data(),
                              point_in_rig);
  for (int r = 0; r < 3; ++r) point_in_rig[r] += rig_from_world[3 + r];
  ceres::AngleAxisRotatePoint(cam_from_rig.data(), point_in_rig, point_in_cam);
  for (int r = 0; r < 3; ++r) point_in_cam[r] += cam_from_rig[3 + r];
  return Eigen::Vector3d(point_in_cam[0], point_in_cam[1], point_in_cam[2]);
}

// Residual and every Jacobian agree with automatic differentiation on
// random poses, including zero and tiny rotations, image points at the
// principal point, points on the wrong half-line (alpha <= 0) and on the
// optical axis.
TEST(RadialRigCostFunction, MatchesAutomaticDifferentiation) {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> unit(-1, 1);
  int num_wrong_half_line = 0;
  int num_on_axis = 0;
  for (int trial = 0; trial < 200; ++trial) {
    std::array<double, 6> cam_from_rig, rig_from_world;
    for (int k = 0; k < 6; ++k) {
      cam_from_rig[k] = (k < 3 ? 1.5 : 0.3) * unit(random);
      rig_from_world[k] = (k < 3 ? 2.0 : 3.0) * unit(random);
    }
    if (trial % 10 == 1) {
      cam_from_rig = {0, 0, 0, 0, 0, 0};  // the reference camera
    } else if (trial % 10 == 2) {
      for (int k = 0; k < 3; ++k) rig_from_world[k] *= 1e-10;
    }
    const std::array<double, 2> principal_point = {320 + 20 * unit(random),
                                                   240 + 20 * unit(random)};
    const Eigen::Vector3d point3D(5 * unit(random), 5 * unit(random),
                                  8 + 2 * unit(random));
    Eigen::Vector2d point2D(320 + 300 * unit(random), 240 + 200 * unit(random));
    if (trial % 10 == 3) {
      point2D = Eigen::Vector2d(principal_point[0], principal_point[1]);
    } else if (trial % 10 == 4) {
      // Move the camera so that the point lands on its optical axis (up to
      // rounding, far below the 1e-12 rad of IsOnOpticalAxis).
      const Eigen::Vector3d point_in_cam =
          PointInCamera(cam_from_rig, rig_from_world, point3D);
      cam_from_rig[3] -= point_in_cam.x();
      cam_from_rig[4] -= point_in_cam.y();
      ASSERT_TRUE(IsOnOpticalAxis(
          PointInCamera(cam_from_rig, rig_from_world, point3D).data()));
    }
    const RadialRigCostFunction analytic(point2D, point3D);
    ceres::AutoDiffCostFunction<RadialRigResidual, 2, 6, 6, 2> automatic(
        new RadialRigResidual{point2D, point3D});
    const Evaluation expected =
        Evaluate(automatic, cam_from_rig, rig_from_world, principal_point);
    const Evaluation actual =
        Evaluate(analytic, cam_from_rig, rig_from_world, principal_point);
    SCOPED_TRACE("trial " + std::to_string(trial));
    ExpectNear(actual.residual, expected.residual, 1e-9, "residual");
    ExpectNear(actual.jacobian_cam, expected.jacobian_cam, 1e-7,
               "d/cam_from_rig");
    ExpectNear(actual.jacobian_rig, expected.jacobian_rig, 1e-7,
               "d/rig_from_world");
    ExpectNear(actual.jacobian_principal_point,
               expected.jacobian_principal_point, 1e-12, "d/principal point");
    const bool residual_is_x_minus_c =
        actual.residual[0] == point2D.x() - principal_point[0] &&
        actual.residual[1] == point2D.y() - principal_point[1];
    if (trial % 10 == 4) {
      // On the axis: e = x - c, no pull on either pose, de/dc = -I.
      EXPECT_TRUE(residual_is_x_minus_c);
      for (const double value : actual.jacobian_cam) EXPECT_EQ(value, 0);
      for (const double value : actual.jacobian_rig) EXPECT_EQ(value, 0);
      EXPECT_EQ(actual.jacobian_principal_point[0], -1);
      EXPECT_EQ(actual.jacobian_principal_point[3], -1);
      ++num_on_axis;
    } else if (trial % 10 != 3) {
      num_wrong_half_line += residual_is_x_minus_c;
    }
  }
  // Every branch of RadialResidual was exercised.
  EXPECT_EQ(num_on_axis, 20);
  EXPECT_GT(num_wrong_half_line, 20);
  EXPECT_LT(num_wrong_half_line, 140);

  // Without Jacobians: the residual only.
  const RadialRigCostFunction cost(Eigen::Vector2d(400, 300),
                                   Eigen::Vector3d(1, 1, 5));
  const std::array<double, 6> identity = {0, 0, 0, 0, 0, 0};
  const std::array<double, 2> center = {320, 240};
  const double* parameters[] = {identity.data(), identity.data(),
                                center.data()};
  double residual[2];
  ASSERT_TRUE(cost.Evaluate(parameters, residual, nullptr));
  // (80, 60) against the line through (1, 1): alpha = 140 / sqrt(2),
  // e = (80, 60) - (70, 70).
  EXPECT_NEAR(residual[0], 10, 1e-12);
  EXPECT_NEAR(residual[1], -10, 1e-12);
}

}  // namespace
}  // namespace rig_calibrator
