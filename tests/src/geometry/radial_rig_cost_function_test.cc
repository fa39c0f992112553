#include "src/geometry/radial_rig_cost_function.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>
#include <gtest/gtest.h>

#include <array>
#include <random>
#include <string>

#include "src/geometry/radial_residual.h"

namespace rig_calibrator {
namespace radial_rig_cost_function_test {

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
    ceres::UnitQuaternionRotatePoint(rig_from_world, point, point_in_rig);
    for (int r = 0; r < 3; ++r) point_in_rig[r] += rig_from_world[4 + r];
    T point_in_cam[3];
    ceres::UnitQuaternionRotatePoint(cam_from_rig, point_in_rig, point_in_cam);
    for (int r = 0; r < 3; ++r) point_in_cam[r] += cam_from_rig[4 + r];
    const T centered[2] = {T(point2D(0)) - principal_point[0],
                           T(point2D(1)) - principal_point[1]};
    RadialResidual(centered, point_in_cam, residuals);
    return true;
  }
};

// The pose Jacobians in the tangent spaces of the manifolds the radial BA
// refines the poses on (RadialCameraPoseManifold: 5, RigPoseManifold: 6).
struct Evaluation {
  std::array<double, 2> residual;
  std::array<double, 10> jacobian_cam;
  std::array<double, 12> jacobian_rig;
  std::array<double, 4> jacobian_principal_point;
};

using Pose = std::array<double, 7>;  // [qw, qx, qy, qz, tx, ty, tz]

// A 2 x 7 ambient Jacobian times the manifold's PlusJacobian (row-major).
template <int kTangent>
std::array<double, 2 * kTangent> OnManifold(const ceres::Manifold& manifold,
                                            const Pose& pose,
                                            const std::array<double, 14>& j) {
  Eigen::Matrix<double, 7, kTangent, Eigen::RowMajor> plus;
  manifold.PlusJacobian(pose.data(), plus.data());
  const Eigen::Matrix<double, 2, kTangent, Eigen::RowMajor> tangent =
      Eigen::Map<const Eigen::Matrix<double, 2, 7, Eigen::RowMajor>>(j.data()) *
      plus;
  std::array<double, 2 * kTangent> out;
  Eigen::Map<Eigen::Matrix<double, 2, kTangent, Eigen::RowMajor>>(out.data()) =
      tangent;
  return out;
}

// Evaluate (ambient Jacobians, mapped onto the manifolds) or, with
// `tangent`, EvaluateTangent of a RadialRigCostFunction.
Evaluation Evaluate(const ceres::CostFunction& cost, const Pose& cam_from_rig,
                    const Pose& rig_from_world,
                    const std::array<double, 2>& principal_point,
                    bool tangent) {
  const RadialCameraPoseManifold cam_manifold = MakeRadialCameraPoseManifold();
  const RigPoseManifold rig_manifold;
  Evaluation evaluation;
  const double* parameters[] = {cam_from_rig.data(), rig_from_world.data(),
                                principal_point.data()};
  if (tangent) {
    const auto& tangent_cost = dynamic_cast<const TangentJacobianCost&>(cost);
    EXPECT_EQ(tangent_cost.TangentSize(0), cam_manifold.TangentSize());
    EXPECT_EQ(tangent_cost.TangentSize(1), rig_manifold.TangentSize());
    EXPECT_EQ(tangent_cost.TangentSize(2), 0);
    double* jacobians[] = {evaluation.jacobian_cam.data(),
                           evaluation.jacobian_rig.data(),
                           evaluation.jacobian_principal_point.data()};
    EXPECT_TRUE(tangent_cost.EvaluateTangent(
        parameters, evaluation.residual.data(), jacobians));
    return evaluation;
  }
  std::array<double, 14> cam, rig;
  double* jacobians[] = {cam.data(), rig.data(),
                         evaluation.jacobian_principal_point.data()};
  EXPECT_TRUE(cost.Evaluate(parameters, evaluation.residual.data(), jacobians));
  evaluation.jacobian_cam = OnManifold<5>(cam_manifold, cam_from_rig, cam);
  evaluation.jacobian_rig = OnManifold<6>(rig_manifold, rig_from_world, rig);
  return evaluation;
}

// A pose [q, t] from a rotation vector and a translation.
Pose MakePose(const Eigen::Vector3d& rotation, const Eigen::Vector3d& t) {
  const double angle = rotation.norm();
  const Eigen::Quaterniond q =
      angle > 0 ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, rotation / angle))
                : Eigen::Quaterniond::Identity();
  return {q.w(), q.x(), q.y(), q.z(), t.x(), t.y(), t.z()};
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
Eigen::Vector3d PointInCamera(const Pose& cam_from_rig,
                              const Pose& rig_from_world,
                              const Eigen::Vector3d& point3D) {
  double point_in_rig[3], point_in_cam[3];
  ceres::UnitQuaternionRotatePoint(rig_from_world.data(), point3D.data(),
                                   point_in_rig);
  for (int r = 0; r < 3; ++r) point_in_rig[r] += rig_from_world[4 + r];
  ceres::UnitQuaternionRotatePoint(cam_from_rig.data(), point_in_rig,
                                   point_in_cam);
  for (int r = 0; r < 3; ++r) point_in_cam[r] += cam_from_rig[4 + r];
  return Eigen::Vector3d(point_in_cam[0], point_in_cam[1], point_in_cam[2]);
}

// Residual and every Jacobian, ambient and in the tangent spaces, agree
// with automatic differentiation on random poses, including zero and tiny
// rotations, image points at the principal point, points on the wrong
// half-line (alpha <= 0) and on the optical axis.
TEST(RadialRigCostFunction, MatchesAutomaticDifferentiation) {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> unit(-1, 1);
  int num_wrong_half_line = 0;
  int num_on_axis = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const auto random_vector = [&](double scale) {
      return Eigen::Vector3d(scale * unit(random), scale * unit(random),
                             scale * unit(random));
    };
    Pose cam_from_rig = MakePose(random_vector(1.5), random_vector(0.3));
    Pose rig_from_world = MakePose(random_vector(2.0), random_vector(3.0));
    if (trial % 10 == 1) {
      cam_from_rig = {1, 0, 0, 0, 0, 0, 0};  // the reference camera
    } else if (trial % 10 == 2) {
      rig_from_world = MakePose(1e-10 * random_vector(2.0), random_vector(3));
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
      cam_from_rig[4] -= point_in_cam.x();
      cam_from_rig[5] -= point_in_cam.y();
      ASSERT_TRUE(IsOnOpticalAxis(
          PointInCamera(cam_from_rig, rig_from_world, point3D).data()));
    }
    const RadialRigCostFunction analytic(point2D, point3D);
    ceres::AutoDiffCostFunction<RadialRigResidual, 2, 7, 7, 2> automatic(
        new RadialRigResidual{point2D, point3D});
    const Evaluation expected =
        Evaluate(automatic, cam_from_rig, rig_from_world, principal_point,
                 /*tangent=*/false);
    for (const bool tangent : {false, true}) {
      const Evaluation actual = Evaluate(analytic, cam_from_rig, rig_from_world,
                                         principal_point, tangent);
      SCOPED_TRACE("trial " + std::to_string(trial) +
                   (tangent ? ", tangent" : ", ambient"));
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
      } else if (trial % 10 != 3 && !tangent) {
        num_wrong_half_line += residual_is_x_minus_c;
      }
    }
  }
  // Every branch of RadialResidual was exercised.
  EXPECT_EQ(num_on_axis, 40);  // ambient and tangent
  EXPECT_GT(num_wrong_half_line, 20);
  EXPECT_LT(num_wrong_half_line, 140);

  // Without Jacobians: the residual only.
  const RadialRigCostFunction cost(Eigen::Vector2d(400, 300),
                                   Eigen::Vector3d(1, 1, 5));
  const Pose identity = {1, 0, 0, 0, 0, 0, 0};
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

}  // namespace radial_rig_cost_function_test
}  // namespace rig_calibrator
