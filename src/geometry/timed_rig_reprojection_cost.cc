#include "src/geometry/timed_rig_reprojection_cost.h"

#include <ceres/autodiff_cost_function.h>
#include <colmap/base/camera_models.h>

namespace rig_calibrator {
namespace {

// r = pi_theta(P Exp(-u(tau)) (Q X - p(tau))) - x (see the header).
template <typename CameraModel, typename T>
bool TimedResidual(const T* rig_from_world, const T* cam_from_rig,
                   const T* params, const T& time_offset, const T& line_delay,
                   const FramesetMotion& motion, const T* point,
                   const Eigen::Vector2d& observed, T* residuals) {
  const T tau = CaptureTimeOfRow(time_offset, line_delay, observed.y());
  T point_in_rig[3];
  WorldToRigAtOffset(rig_from_world, point, motion, tau, point_in_rig);
  T point_in_cam[3];
  ceres::QuaternionRotatePoint(cam_from_rig, point_in_rig, point_in_cam);
  for (int k = 0; k < 3; ++k) point_in_cam[k] += cam_from_rig[4 + k];
  if (!(point_in_cam[2] > 0.0)) return false;
  CameraModel::WorldToImage(params, point_in_cam[0] / point_in_cam[2],
                            point_in_cam[1] / point_in_cam[2], &residuals[0],
                            &residuals[1]);
  residuals[0] -= observed.x();
  residuals[1] -= observed.y();
  return true;
}

// The point fixed at construction.
template <typename CameraModel>
struct TimedCostFixedPoint {
  template <typename T>
  bool operator()(const T* rig_from_world, const T* cam_from_rig,
                  const T* params, const T* time_offset, const T* line_delay,
                  T* residuals) const {
    const T point[3] = {T(point3D.x()), T(point3D.y()), T(point3D.z())};
    return TimedResidual<CameraModel>(rig_from_world, cam_from_rig, params,
                                      time_offset[0], line_delay[0], *motion,
                                      point, observed, residuals);
  }
  Eigen::Vector2d observed;
  Eigen::Vector3d point3D;
  const FramesetMotion* motion;
};

// The point the sixth block.
template <typename CameraModel>
struct TimedCostRefinedPoint {
  template <typename T>
  bool operator()(const T* rig_from_world, const T* cam_from_rig,
                  const T* params, const T* time_offset, const T* line_delay,
                  const T* point, T* residuals) const {
    return TimedResidual<CameraModel>(rig_from_world, cam_from_rig, params,
                                      time_offset[0], line_delay[0], *motion,
                                      point, observed, residuals);
  }
  Eigen::Vector2d observed;
  const FramesetMotion* motion;
};

template <typename CameraModel>
ceres::CostFunction* CreateTimedCost(const Eigen::Vector2d& observed,
                                     const Eigen::Vector3d* point3D,
                                     const FramesetMotion* motion) {
  constexpr int kNumParams = static_cast<int>(CameraModel::kNumParams);
  if (point3D != nullptr) {
    return new ceres::AutoDiffCostFunction<TimedCostFixedPoint<CameraModel>,
                                           2, 7, 7, kNumParams, 1, 1>(
        new TimedCostFixedPoint<CameraModel>{observed, *point3D, motion});
  }
  return new ceres::AutoDiffCostFunction<TimedCostRefinedPoint<CameraModel>,
                                         2, 7, 7, kNumParams, 1, 1, 3>(
      new TimedCostRefinedPoint<CameraModel>{observed, motion});
}

}  // namespace

ceres::CostFunction* CreateTimedRigReprojectionCost(
    int model_id, const Eigen::Vector2d& observed,
    const Eigen::Vector3d* point3D, const FramesetMotion* motion) {
  switch (model_id) {
#define CAMERA_MODEL_CASE(CameraModel) \
  case colmap::CameraModel::kModelId:  \
    return CreateTimedCost<colmap::CameraModel>(observed, point3D, motion);
    CAMERA_MODEL_CASES
#undef CAMERA_MODEL_CASE
    default:
      return nullptr;
  }
}

}  // namespace rig_calibrator
