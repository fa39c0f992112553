#include "src/geometry/full_reprojection_cost.h"

#include <ceres/autodiff_cost_function.h>
#include <colmap/base/camera.h>
#include <colmap/base/camera_models.h>
#include <gtest/gtest.h>

#include <memory>

namespace rig_calibrator {
namespace full_reprojection_cost_test {

// The residual with Ceres' automatic differentiation: the reference.
template <typename CameraModel>
struct AutoDiffFullReprojectionError {
  template <typename T>
  bool operator()(const T* tz, const T* params, T* residuals) const {
    const T depth = T(point_cam.z()) + tz[0];
    CameraModel::WorldToImage(params, T(point_cam.x()) / depth,
                              T(point_cam.y()) / depth, &residuals[0],
                              &residuals[1]);
    residuals[0] -= T(observed.x());
    residuals[1] -= T(observed.y());
    return true;
  }
  Eigen::Vector2d observed;
  Eigen::Vector3d point_cam;
};

template <typename CameraModel>
void ExpectMatchesAutoDiff() {
  SCOPED_TRACE(CameraModel::model_name);
  constexpr int kNumParams = static_cast<int>(CameraModel::kNumParams);
  colmap::Camera camera;
  camera.InitializeWithId(CameraModel::kModelId, 450, 640, 480);
  for (size_t k : camera.ExtraParamsIdxs()) {
    camera.Params(k) = 0.03 * (k % 2 == 0 ? 1 : -1) * (1 + k);
  }
  const Eigen::Vector2d observed(300, 200);
  const double tz[] = {0.4};
  for (const Eigen::Vector3d& point_cam :
       {Eigen::Vector3d(0.5, -0.3, 2.0), Eigen::Vector3d(-1.5, 0.8, 1.1),
        Eigen::Vector3d(0, 0, 3)}) {
    SCOPED_TRACE(testing::Message() << point_cam.transpose());
    const double* parameters[] = {tz, camera.ParamsData()};
    FullReprojectionCost<CameraModel> cost(observed, point_cam);
    ceres::AutoDiffCostFunction<AutoDiffFullReprojectionError<CameraModel>, 2,
                                1, kNumParams>
        reference(new AutoDiffFullReprojectionError<CameraModel>{observed,
                                                                 point_cam});
    Eigen::Vector2d residual, expected_residual, residual_only;
    Eigen::Vector2d d_tz, expected_d_tz;
    Eigen::Matrix<double, 2, kNumParams, Eigen::RowMajor> d_params,
        expected_d_params;
    double* jacobians[] = {d_tz.data(), d_params.data()};
    double* expected_jacobians[] = {expected_d_tz.data(),
                                    expected_d_params.data()};
    ASSERT_TRUE(cost.Evaluate(parameters, residual.data(), jacobians));
    ASSERT_TRUE(reference.Evaluate(parameters, expected_residual.data(),
                                   expected_jacobians));
    EXPECT_LT((residual - expected_residual).norm(), 1e-10);
    EXPECT_LT((d_tz - expected_d_tz).norm(),
              1e-10 * expected_d_tz.norm() + 1e-12);
    EXPECT_LT((d_params - expected_d_params).norm(),
              1e-10 * expected_d_params.norm());
    ASSERT_TRUE(cost.Evaluate(parameters, residual_only.data(), nullptr));
    EXPECT_LT((residual_only - residual).norm(), 1e-10);
  }
  // On the camera plane: a failed evaluation, not a NaN or infinity.
  FullReprojectionCost<CameraModel> on_plane(observed,
                                             Eigen::Vector3d(0.1, 0.2, -0.4));
  const double* parameters[] = {tz, camera.ParamsData()};
  Eigen::Vector2d residual;
  EXPECT_FALSE(on_plane.Evaluate(parameters, residual.data(), nullptr));
}

TEST(FullReprojectionCost, JacobiansMatchAutoDiff) {
  ExpectMatchesAutoDiff<colmap::SimpleRadialCameraModel>();
  ExpectMatchesAutoDiff<colmap::RadialCameraModel>();
  ExpectMatchesAutoDiff<colmap::OpenCVCameraModel>();
  ExpectMatchesAutoDiff<colmap::OpenCVFisheyeCameraModel>();
  ExpectMatchesAutoDiff<colmap::FullOpenCVCameraModel>();
  ExpectMatchesAutoDiff<colmap::ThinPrismFisheyeCameraModel>();
}

}  // namespace full_reprojection_cost_test
}  // namespace rig_calibrator
