#include "src/geometry/timed_rig_reprojection_cost.h"

#include <colmap/base/camera_models.h>

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "src/geometry/camera_model_jacobians.h"
#include "src/geometry/pose_interpolation.h"
#include "src/geometry/pose_jacobians.h"

namespace rig_calibrator {
namespace {

// r = pi_theta(P Exp(-u(tau)) (Q X - p(tau))) - x with the Jacobians of the
// header.
template <typename CameraModel>
class TimedRigReprojectionCost final
    : public RigPosesTangentCost<TimedRigReprojectionCost<CameraModel>> {
 public:
  static constexpr int kNumParams = static_cast<int>(CameraModel::kNumParams);

  TimedRigReprojectionCost(const Eigen::Vector2d& observed,
                           const Eigen::Vector3d* point3D,
                           const FramesetMotion* motion)
      : observed_(observed),
        fixed_point3D_(point3D != nullptr ? *point3D : Eigen::Vector3d::Zero()),
        variable_point_(point3D == nullptr),
        motion_(motion) {
    this->set_num_residuals(2);
    *this->mutable_parameter_block_sizes() =
        variable_point_ ? std::vector<int32_t>{7, 7, kNumParams, 1, 1, 6, 3}
                        : std::vector<int32_t>{7, 7, kNumParams, 1, 1, 6};
  }

  // Evaluate and EvaluateTangent (RigPosesTangentCost): the poses'
  // Jacobians ambient, or 2 x 6 in RigPoseManifold's tangent space.
  template <bool kTangent>
  bool EvaluateImpl(double const* const* parameters, double* residuals,
                    double** jacobians) const {
    const double* rig_from_world = parameters[0];
    const double* cam_from_rig = parameters[1];
    const double* camera_params = parameters[2];
    const FramesetMotion& motion = *motion_;
    const Eigen::Quaterniond rig_rotation(rig_from_world[0], rig_from_world[1],
                                          rig_from_world[2], rig_from_world[3]);
    const Eigen::Quaterniond cam_rotation(cam_from_rig[0], cam_from_rig[1],
                                          cam_from_rig[2], cam_from_rig[3]);
    const Eigen::Matrix3d rig_rotation_matrix = rig_rotation.toRotationMatrix();
    const Eigen::Matrix3d cam_rotation_matrix = cam_rotation.toRotationMatrix();
    const Eigen::Vector3d point3D =
        variable_point_ ? Eigen::Vector3d(parameters[6]) : fixed_point3D_;

    // u(tau), p(tau) and their derivatives in tau (frameset_motion.h).
    const double tau =
        CaptureTimeOfRow(parameters[3][0], parameters[4][0], observed_.y());
    const double a1 = tau, a2 = tau * tau / 2, a3 = tau * tau * tau / 6;
    const Eigen::Map<const Eigen::Vector3d> u1(&motion[0]), u2(&motion[3]),
        u3(&motion[6]), p1(parameters[5]), p2(parameters[5] + 3),
        p3(&motion[15]);
    const Eigen::Vector3d phi = -(a1 * u1 + a2 * u2 + a3 * u3);
    const Eigen::Vector3d p = a1 * p1 + a2 * p2 + a3 * p3;

    const Eigen::Vector3d rig_rotated = rig_rotation_matrix * point3D;
    const Eigen::Vector3d w =
        rig_rotated + Eigen::Vector3d(rig_from_world + 4) - p;
    const Eigen::Matrix3d motion_rotation = ExpSO3(phi);
    const Eigen::Vector3d point_in_rig = motion_rotation * w;
    const Eigen::Vector3d cam_rotated = cam_rotation_matrix * point_in_rig;
    const Eigen::Vector3d point_in_cam =
        cam_rotated + Eigen::Vector3d(cam_from_rig + 4);
    if (jacobians == nullptr) {
      return ProjectCameraPoint<CameraModel>(camera_params, point_in_cam,
                                             observed_, residuals, nullptr,
                                             nullptr);
    }
    Eigen::Matrix<double, 2, 3> d_pixel_d_cam;
    if (!ProjectCameraPoint<CameraModel>(camera_params, point_in_cam,
                                         observed_, residuals, &d_pixel_d_cam,
                                         jacobians[2])) {
      return false;
    }
    if (jacobians[1] != nullptr) {
      WritePoseJacobian<kTangent, 2>(d_pixel_d_cam, cam_rotation, point_in_rig,
                                     cam_rotated, jacobians[1]);
    }
    const Eigen::Matrix<double, 2, 3> d_pixel_d_rig =
        d_pixel_d_cam * cam_rotation_matrix;
    const Eigen::Matrix<double, 2, 3> d_pixel_d_frameset =
        d_pixel_d_rig * motion_rotation;
    if (jacobians[0] != nullptr) {
      WritePoseJacobian<kTangent, 2>(d_pixel_d_frameset, rig_rotation, point3D,
                                     rig_rotated, jacobians[0]);
    }
    if (jacobians[3] != nullptr || jacobians[4] != nullptr) {
      const Eigen::Vector3d du = u1 + tau * u2 + a2 * u3;
      const Eigen::Vector3d dp = p1 + tau * p2 + a2 * p3;
      const Eigen::Vector3d d_point_d_tau =
          motion_rotation * (w.cross(RightJacobianSO3(phi) * du) - dp);
      const Eigen::Vector2d d_pixel_d_tau = d_pixel_d_rig * d_point_d_tau;
      if (jacobians[3] != nullptr) {
        jacobians[3][0] = d_pixel_d_tau.x();
        jacobians[3][1] = d_pixel_d_tau.y();
      }
      if (jacobians[4] != nullptr) {
        const double row = observed_.y() - 0.5;
        jacobians[4][0] = d_pixel_d_tau.x() * row;
        jacobians[4][1] = d_pixel_d_tau.y() * row;
      }
    }
    if (jacobians[5] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 2, 6, Eigen::RowMajor>> jacobian(
          jacobians[5]);
      jacobian.leftCols<3>() = -tau * d_pixel_d_frameset;
      jacobian.rightCols<3>() = -a2 * d_pixel_d_frameset;
    }
    if (variable_point_ && jacobians[6] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> jacobian(
          jacobians[6]);
      jacobian = d_pixel_d_frameset * rig_rotation_matrix;
    }
    return true;
  }

 private:
  const Eigen::Vector2d observed_;
  const Eigen::Vector3d fixed_point3D_;
  const bool variable_point_;
  const FramesetMotion* motion_;
};

}  // namespace

ceres::CostFunction* CreateTimedRigReprojectionCost(
    int model_id, const Eigen::Vector2d& observed,
    const Eigen::Vector3d* point3D, const FramesetMotion* motion) {
  switch (model_id) {
#define CAMERA_MODEL_CASE(CameraModel)                                  \
  case colmap::CameraModel::kModelId:                                   \
    return new TimedRigReprojectionCost<colmap::CameraModel>(observed, \
                                                             point3D, motion);
    CAMERA_MODEL_CASES
#undef CAMERA_MODEL_CASE
    default:
      return nullptr;
  }
}

}  // namespace rig_calibrator
