// The time model's reprojection cost: its residual and analytic Jacobians
// (poses on RigPoseManifold, intrinsics, offset, line delay, velocity and
// acceleration, point) against
// automatic differentiation of the header's formula, for every kind of
// camera model, a fixed and a refined point, with and without the constant
// blocks' Jacobians; a point behind the camera is an invalid evaluation.
#include "src/geometry/timed_rig_reprojection_cost.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <colmap/base/camera.h>
#include <colmap/base/camera_models.h>
#include <gtest/gtest.h>

#include <array>
#include <memory>

#include "src/geometry/pose_jacobians.h"
#include "src/geometry/rigid3d.h"

namespace rig_calibrator {
namespace timed_rig_reprojection_cost_test {

// The header's r, automatically differentiated: the reference.
template <typename CameraModel>
struct AutoDiffTimedError {
  template <typename T>
  bool operator()(const T* rig_from_world, const T* cam_from_rig,
                  const T* params, const T* time_offset, const T* line_delay,
                  const T* translation, const T* point, T* residuals) const {
    const T tau = CaptureTimeOfRow(time_offset[0], line_delay[0], observed.y());
    T point_in_rig[3], point_in_cam[3];
    WorldToRigAtOffset(rig_from_world, point, *motion, translation, tau,
                       point_in_rig);
    ceres::QuaternionRotatePoint(cam_from_rig, point_in_rig, point_in_cam);
    for (int k = 0; k < 3; ++k) point_in_cam[k] += cam_from_rig[4 + k];
    CameraModel::WorldToImage(params, point_in_cam[0] / point_in_cam[2],
                              point_in_cam[1] / point_in_cam[2], &residuals[0],
                              &residuals[1]);
    residuals[0] -= observed.x();
    residuals[1] -= observed.y();
    return true;
  }
  Eigen::Vector2d observed;
  const FramesetMotion* motion;
};

std::array<double, 7> PoseBlock(const Rigid3d& pose) {
  return {pose.rotation.w(),    pose.rotation.x(),    pose.rotation.y(),
          pose.rotation.z(),    pose.translation.x(), pose.translation.y(),
          pose.translation.z()};
}

// A pose block's ambient 2 x 7 Jacobian in RigPoseManifold's tangent space.
Eigen::Matrix<double, 2, 6> Tangent(
    const std::array<double, 7>& block,
    const Eigen::Matrix<double, 2, 7, Eigen::RowMajor>& jacobian) {
  Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus_jacobian;
  RigPoseManifold().PlusJacobian(block.data(), plus_jacobian.data());
  return jacobian * plus_jacobian;
}

template <typename CameraModel>
void ExpectJacobiansMatchAutoDiff() {
  SCOPED_TRACE(CameraModel::model_name);
  constexpr int kNumParams = static_cast<int>(CameraModel::kNumParams);
  const Rigid3d rig_from_world(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())),
      Eigen::Vector3d(0.3, -1, 2));
  const Rigid3d cam_from_rig(
      Eigen::Quaterniond(Eigen::AngleAxisd(2.0, Eigen::Vector3d(-1, 1, 0).normalized())),
      Eigen::Vector3d(0.1, 0.05, -0.2));
  Eigen::Vector3d point3D =
      (cam_from_rig * rig_from_world).Inverse() * Eigen::Vector3d(1.2, -0.8, 3);
  colmap::Camera camera;
  camera.InitializeWithId(CameraModel::kModelId, 500, 640, 480);
  for (size_t k : camera.ExtraParamsIdxs()) {
    camera.Params(k) = 0.02 * (k % 2 == 0 ? 1 : -1) * (1 + k);
  }
  // A walk's motion: 1 rad/s turning and 1.5 m/s with their derivatives.
  const FramesetMotion motion = {0.3, -1.0, 0.2,  2.0, 0.5,  -1.0,
                                 -4.0, 3.0, 6.0,  1.5, -0.2, 0.1,
                                 0.4, 2.0, -0.5, -3.0, 1.0, 5.0};
  double time_offset = 0.041, line_delay = 27e-6;
  // The estimated velocity and acceleration, which replace the motion's p1
  // and p2.
  TranslationDerivatives translation;
  translation << 1.2, 0.3, -0.4, 1.5, -2.5, 0.7;
  std::array<double, 7> rig_block = PoseBlock(rig_from_world);
  std::array<double, 7> cam_block = PoseBlock(cam_from_rig);
  const Eigen::Vector2d observed(100, 400.3);
  const double* parameters[] = {rig_block.data(), cam_block.data(),
                                camera.ParamsData(), &time_offset,
                                &line_delay,        translation.data(),
                                point3D.data()};

  Eigen::Vector2d expected_residual;
  Eigen::Matrix<double, 2, 7, Eigen::RowMajor> expected_rig, expected_cam;
  Eigen::Matrix<double, 2, kNumParams, Eigen::RowMajor> expected_params;
  Eigen::Vector2d expected_offset, expected_delay;
  Eigen::Matrix<double, 2, 6, Eigen::RowMajor> expected_translation;
  Eigen::Matrix<double, 2, 3, Eigen::RowMajor> expected_point;
  double* expected_jacobians[] = {
      expected_rig.data(),      expected_cam.data(),
      expected_params.data(),   expected_offset.data(),
      expected_delay.data(),    expected_translation.data(),
      expected_point.data()};
  ceres::AutoDiffCostFunction<AutoDiffTimedError<CameraModel>, 2, 7, 7,
                              kNumParams, 1, 1, 6, 3>
      reference(new AutoDiffTimedError<CameraModel>{observed, &motion});
  ASSERT_TRUE(reference.Evaluate(parameters, expected_residual.data(),
                                 expected_jacobians));
  // The rolling shutter moves the projection: a non-trivial tau derivative.
  ASSERT_GT(expected_offset.norm(), 1.0);

  for (const bool variable_point : {false, true}) {
    SCOPED_TRACE(variable_point ? "refined point" : "fixed point");
    const std::unique_ptr<ceres::CostFunction> cost(
        CreateTimedRigReprojectionCost(CameraModel::kModelId, observed,
                                       variable_point ? nullptr : &point3D,
                                       &motion));
    ASSERT_NE(cost, nullptr);
    ASSERT_EQ(cost->parameter_block_sizes().size(), variable_point ? 7u : 6u);
    const auto* tangent_cost =
        dynamic_cast<const TangentJacobianCost*>(cost.get());
    ASSERT_NE(tangent_cost, nullptr);
    EXPECT_EQ(tangent_cost->TangentSize(0), 6);
    EXPECT_EQ(tangent_cost->TangentSize(1), 6);
    EXPECT_EQ(tangent_cost->TangentSize(3), 0);
    for (const bool tangent : {false, true}) {
      SCOPED_TRACE(tangent ? "tangent" : "ambient");
      Eigen::Vector2d residual;
      Eigen::Matrix<double, 2, 7, Eigen::RowMajor> rig_jacobian, cam_jacobian;
      Eigen::Matrix<double, 2, kNumParams, Eigen::RowMajor> params_jacobian;
      Eigen::Vector2d offset_jacobian, delay_jacobian;
      Eigen::Matrix<double, 2, 6, Eigen::RowMajor> translation_jacobian;
      Eigen::Matrix<double, 2, 3, Eigen::RowMajor> point_jacobian;
      double* jacobians[] = {rig_jacobian.data(),      cam_jacobian.data(),
                             params_jacobian.data(),   offset_jacobian.data(),
                             delay_jacobian.data(),    translation_jacobian.data(),
                             point_jacobian.data()};
      ASSERT_TRUE(tangent ? tangent_cost->EvaluateTangent(
                                parameters, residual.data(), jacobians)
                          : cost->Evaluate(parameters, residual.data(),
                                           jacobians));
      const double scale = 1e-10 * expected_rig.norm();
      EXPECT_LT((residual - expected_residual).norm(), 1e-10);
      const auto pose_jacobian =
          [&](const Eigen::Matrix<double, 2, 7, Eigen::RowMajor>& jacobian,
              const std::array<double, 7>& block) {
            if (!tangent) return Tangent(block, jacobian);
            return Eigen::Matrix<double, 2, 6>(
                Eigen::Map<const Eigen::Matrix<double, 2, 6, Eigen::RowMajor>>(
                    jacobian.data()));
          };
      EXPECT_LT((pose_jacobian(rig_jacobian, rig_block) -
                 Tangent(rig_block, expected_rig))
                    .norm(),
                scale);
      EXPECT_LT((pose_jacobian(cam_jacobian, cam_block) -
                 Tangent(cam_block, expected_cam))
                    .norm(),
                scale);
      EXPECT_LT((params_jacobian - expected_params).norm(),
                1e-10 * expected_params.norm());
      EXPECT_LT((offset_jacobian - expected_offset).norm(),
                1e-9 * expected_offset.norm());
      EXPECT_LT((delay_jacobian - expected_delay).norm(),
                1e-9 * expected_delay.norm());
      EXPECT_LT((translation_jacobian - expected_translation).norm(),
                1e-10 * expected_translation.norm());
      if (variable_point) {
        EXPECT_LT((point_jacobian - expected_point).norm(), scale);
      }
      // Constant blocks (the reference camera's offset, the intrinsics):
      // no Jacobian asked, the others unchanged.
      jacobians[2] = nullptr;
      jacobians[3] = nullptr;
      delay_jacobian.setZero();
      ASSERT_TRUE(tangent ? tangent_cost->EvaluateTangent(
                                parameters, residual.data(), jacobians)
                          : cost->Evaluate(parameters, residual.data(),
                                           jacobians));
      EXPECT_LT((delay_jacobian - expected_delay).norm(),
                1e-9 * expected_delay.norm());
    }
  }
  // Behind the camera: a failed evaluation, not a NaN.
  const Eigen::Vector3d behind = (cam_from_rig * rig_from_world).Inverse() *
                                 Eigen::Vector3d(0.2, 0.1, -3);
  const std::unique_ptr<ceres::CostFunction> cost(
      CreateTimedRigReprojectionCost(CameraModel::kModelId, observed, &behind,
                                     &motion));
  Eigen::Vector2d residual;
  EXPECT_FALSE(cost->Evaluate(parameters, residual.data(), nullptr));
}

TEST(TimedRigReprojectionCost, JacobiansMatchAutoDiffForEveryModel) {
  ExpectJacobiansMatchAutoDiff<colmap::SimplePinholeCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::SimpleRadialCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::OpenCVCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::OpenCVFisheyeCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::FullOpenCVCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::FOVCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::ThinPrismFisheyeCameraModel>();
  const FramesetMotion motion{};
  EXPECT_EQ(CreateTimedRigReprojectionCost(-7, Eigen::Vector2d::Zero(),
                                           nullptr, &motion),
            nullptr);
}

}  // namespace timed_rig_reprojection_cost_test
}  // namespace rig_calibrator
