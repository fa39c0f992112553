#include "src/geometry/rig_reprojection_cost.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <colmap/base/camera.h>
#include <colmap/base/camera_models.h>
#include <gtest/gtest.h>

#include <array>
#include <memory>

#include "src/geometry/rigid3d.h"

namespace rig_calibrator {
namespace rig_reprojection_cost_test {

Eigen::Quaterniond RotationAboutAxis(double angle_rad,
                                     const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, axis.normalized()));
}

// r = pi_theta(P Q X) - x fully auto-differentiated, with Ceres' own
// quaternion rotation: the reference for the analytic Jacobians.
template <typename CameraModel>
struct AutoDiffRigReprojectionError {
  template <typename T>
  bool operator()(const T* rig_from_world, const T* cam_from_rig,
                  const T* camera_params, const T* point3D,
                  T* residuals) const {
    T point_in_rig[3], point_in_cam[3];
    ceres::UnitQuaternionRotatePoint(rig_from_world, point3D, point_in_rig);
    for (int k = 0; k < 3; ++k) {
      point_in_rig[k] += rig_from_world[4 + k];
    }
    ceres::UnitQuaternionRotatePoint(cam_from_rig, point_in_rig, point_in_cam);
    for (int k = 0; k < 3; ++k) {
      point_in_cam[k] += cam_from_rig[4 + k];
    }
    CameraModel::WorldToImage(camera_params, point_in_cam[0] / point_in_cam[2],
                              point_in_cam[1] / point_in_cam[2], &residuals[0],
                              &residuals[1]);
    residuals[0] -= observed.x();
    residuals[1] -= observed.y();
    return true;
  }
  Eigen::Vector2d observed;
};

template <typename CameraModel>
void ExpectJacobiansMatchAutoDiff() {
  SCOPED_TRACE(CameraModel::model_name);
  constexpr int kNumParams = static_cast<int>(CameraModel::kNumParams);
  const Rigid3d rig_from_world(RotationAboutAxis(0.7, Eigen::Vector3d(1, 2, 3)),
                               Eigen::Vector3d(0.3, -1, 2));
  const Rigid3d cam_from_rig(RotationAboutAxis(2.0, Eigen::Vector3d(-1, 1, 0)),
                             Eigen::Vector3d(0.1, 0.05, -0.2));
  const Rigid3d cam_from_world = cam_from_rig * rig_from_world;
  Eigen::Vector3d point3D =
      cam_from_world.Inverse() * Eigen::Vector3d(1.2, -0.8, 3);
  colmap::Camera camera;
  camera.InitializeWithId(CameraModel::kModelId, 500, 640, 480);
  for (size_t k : camera.ExtraParamsIdxs()) {
    camera.Params(k) = 0.02 * (k % 2 == 0 ? 1 : -1) * (1 + k);
  }
  const auto pose_block = [](const Rigid3d& pose) {
    return std::array<double, 7>{pose.rotation.w(),    pose.rotation.x(),
                                 pose.rotation.y(),    pose.rotation.z(),
                                 pose.translation.x(), pose.translation.y(),
                                 pose.translation.z()};
  };
  const std::array<double, 7> rig_block = pose_block(rig_from_world);
  const std::array<double, 7> cam_block = pose_block(cam_from_rig);
  const Eigen::Vector2d observed(100, 200);
  const double* parameters[] = {rig_block.data(), cam_block.data(),
                                camera.ParamsData(), point3D.data()};

  Eigen::Vector2d expected_residual;
  Eigen::Matrix<double, 2, 7, Eigen::RowMajor> expected_rig, expected_cam;
  Eigen::Matrix<double, 2, kNumParams, Eigen::RowMajor> expected_params;
  Eigen::Matrix<double, 2, 3, Eigen::RowMajor> expected_point;
  double* expected_jacobians[] = {expected_rig.data(), expected_cam.data(),
                                  expected_params.data(),
                                  expected_point.data()};
  ceres::AutoDiffCostFunction<AutoDiffRigReprojectionError<CameraModel>, 2, 7,
                              7, kNumParams, 3>
      reference(new AutoDiffRigReprojectionError<CameraModel>{observed});
  ASSERT_TRUE(reference.Evaluate(parameters, expected_residual.data(),
                                 expected_jacobians));
  EXPECT_NEAR((expected_residual -
               (camera.WorldToImage((cam_from_world * point3D).hnormalized()) -
                observed))
                  .norm(),
              0, 1e-9);

  // Pose Jacobians are compared on the manifold (what Ceres uses).
  const ceres::QuaternionManifold quaternion_manifold;
  const auto on_manifold =
      [&](const std::array<double, 7>& block,
          const Eigen::Matrix<double, 2, 7, Eigen::RowMajor>& jacobian) {
        Eigen::Matrix<double, 4, 3, Eigen::RowMajor> plus_jacobian;
        quaternion_manifold.PlusJacobian(block.data(), plus_jacobian.data());
        Eigen::Matrix<double, 2, 6> tangent;
        tangent << jacobian.leftCols<4>() * plus_jacobian,
            jacobian.rightCols<3>();
        return tangent;
      };
  for (const bool variable_point : {false, true}) {
    SCOPED_TRACE(variable_point ? "variable point" : "fixed point");
    const std::unique_ptr<ceres::CostFunction> cost(CreateRigReprojectionCost(
        CameraModel::kModelId, observed, variable_point ? nullptr : &point3D));
    ASSERT_NE(cost, nullptr);
    ASSERT_EQ(cost->parameter_block_sizes().size(), variable_point ? 4 : 3);
    Eigen::Vector2d residual;
    Eigen::Matrix<double, 2, 7, Eigen::RowMajor> rig_jacobian, cam_jacobian;
    Eigen::Matrix<double, 2, kNumParams, Eigen::RowMajor> params_jacobian;
    Eigen::Matrix<double, 2, 3, Eigen::RowMajor> point_jacobian;
    double* jacobians[] = {rig_jacobian.data(), cam_jacobian.data(),
                           params_jacobian.data(), point_jacobian.data()};
    ASSERT_TRUE(cost->Evaluate(parameters, residual.data(), jacobians));
    const double scale = 1e-10 * expected_rig.norm();
    EXPECT_LT((residual - expected_residual).norm(), 1e-10);
    EXPECT_LT((on_manifold(rig_block, rig_jacobian) -
               on_manifold(rig_block, expected_rig))
                  .norm(),
              scale);
    EXPECT_LT((on_manifold(cam_block, cam_jacobian) -
               on_manifold(cam_block, expected_cam))
                  .norm(),
              scale);
    EXPECT_LT((params_jacobian - expected_params).norm(),
              1e-10 * expected_params.norm());
    if (variable_point) {
      EXPECT_LT((point_jacobian - expected_point).norm(), scale);
    }
    // In RigPoseManifold's tangent space (the solver's EvaluateTangent): the
    // same residual, the poses' 2 x 6 Jacobians equal to the auto-
    // differentiated ones times the manifold's PlusJacobian, the rest
    // ambient.
    const auto* tangent_cost =
        dynamic_cast<const TangentJacobianCost*>(cost.get());
    ASSERT_NE(tangent_cost, nullptr);
    const RigPoseManifold pose_manifold;
    EXPECT_EQ(tangent_cost->TangentSize(0), pose_manifold.TangentSize());
    EXPECT_EQ(tangent_cost->TangentSize(1), pose_manifold.TangentSize());
    EXPECT_EQ(tangent_cost->TangentSize(2), 0);
    const auto tangent_of =
        [&](const std::array<double, 7>& block,
            const Eigen::Matrix<double, 2, 7, Eigen::RowMajor>& jacobian) {
          Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus_jacobian;
          pose_manifold.PlusJacobian(block.data(), plus_jacobian.data());
          return Eigen::Matrix<double, 2, 6>(jacobian * plus_jacobian);
        };
    Eigen::Vector2d tangent_residual;
    Eigen::Matrix<double, 2, 6, Eigen::RowMajor> rig_tangent, cam_tangent;
    params_jacobian.setZero();
    point_jacobian.setZero();
    double* tangent_jacobians[] = {rig_tangent.data(), cam_tangent.data(),
                                   params_jacobian.data(),
                                   point_jacobian.data()};
    ASSERT_TRUE(tangent_cost->EvaluateTangent(
        parameters, tangent_residual.data(), tangent_jacobians));
    EXPECT_LT((tangent_residual - expected_residual).norm(), 1e-10);
    EXPECT_LT((Eigen::Matrix<double, 2, 6>(rig_tangent) -
               tangent_of(rig_block, expected_rig))
                  .norm(),
              scale);
    EXPECT_LT((Eigen::Matrix<double, 2, 6>(cam_tangent) -
               tangent_of(cam_block, expected_cam))
                  .norm(),
              scale);
    EXPECT_LT((params_jacobian - expected_params).norm(),
              1e-10 * expected_params.norm());
    if (variable_point) {
      EXPECT_LT((point_jacobian - expected_point).norm(), scale);
    }
    // Without the intrinsics' Jacobian (constant block) the rest is the same.
    jacobians[2] = nullptr;
    ASSERT_TRUE(cost->Evaluate(parameters, residual.data(), jacobians));
    EXPECT_LT((on_manifold(rig_block, rig_jacobian) -
               on_manifold(rig_block, expected_rig))
                  .norm(),
              scale);
  }
  // Behind the camera: a failed evaluation, not a NaN.
  const Eigen::Vector3d behind =
      cam_from_world.Inverse() * Eigen::Vector3d(0.2, 0.1, -3);
  const std::unique_ptr<ceres::CostFunction> cost(
      CreateRigReprojectionCost(CameraModel::kModelId, observed, &behind));
  Eigen::Vector2d residual;
  EXPECT_FALSE(cost->Evaluate(parameters, residual.data(), nullptr));
}

TEST(RigReprojectionCost, JacobiansMatchAutoDiffForEveryModel) {
  ExpectJacobiansMatchAutoDiff<colmap::SimplePinholeCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::SimpleRadialCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::OpenCVCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::OpenCVFisheyeCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::FullOpenCVCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::FOVCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::ThinPrismFisheyeCameraModel>();
  EXPECT_EQ(CreateRigReprojectionCost(-7, Eigen::Vector2d::Zero(), nullptr),
            nullptr);
}

}  // namespace rig_reprojection_cost_test
}  // namespace rig_calibrator
