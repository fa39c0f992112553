#include "src/geometry/camera_model_jacobians.h"

#include <colmap/base/camera.h>
#include <colmap/base/camera_models.h>
#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace rig_calibrator {
namespace camera_model_jacobians_test {

// Normalized points from the centre (where the fisheye switches branch) to
// the edge of a wide field of view, and random ones.
std::vector<Eigen::Vector2d> TestPoints() {
  std::vector<Eigen::Vector2d> points = {
      {0, 0},       {1e-17, 0},  {3e-16, -2e-16}, {1e-9, 2e-9}, {1e-5, -3e-6},
      {0.01, 0.02}, {-0.3, 0.2}, {0.7, -0.6},     {1.5, 0.4},   {-2.5, -1.8}};
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-1.2, 1.2);
  for (int k = 0; k < 40; ++k) {
    points.emplace_back(coordinate(random), coordinate(random));
  }
  return points;
}

// The closed form against forward-mode Jets of COLMAP's WorldToImage (and
// the pixel against COLMAP's double WorldToImage), with distortion
// parameters that are not small, for several parameter sets.
template <typename CameraModel>
void ExpectClosedFormMatchesJets() {
  SCOPED_TRACE(CameraModel::model_name);
  static_assert(HasClosedFormJacobians<CameraModel>());
  constexpr int kNumParams = static_cast<int>(CameraModel::kNumParams);
  std::mt19937 random(11);
  std::uniform_real_distribution<double> extra(-0.3, 0.3);
  for (int trial = 0; trial < 5; ++trial) {
    colmap::Camera camera;
    camera.InitializeWithId(CameraModel::kModelId, 400 + 30 * trial, 640, 480);
    if (camera.FocalLengthIdxs().size() == 2) {
      camera.SetFocalLengthY(camera.FocalLengthX() * 1.07);
    }
    camera.SetPrincipalPointX(321.5);
    camera.SetPrincipalPointY(238.25);
    for (size_t k : camera.ExtraParamsIdxs()) {
      camera.Params(k) = trial == 0 ? 0.0 : extra(random);
    }
    for (const Eigen::Vector2d& point : TestPoints()) {
      SCOPED_TRACE(testing::Message()
                   << "trial " << trial << ", point " << point.transpose());
      Eigen::Vector2d pixel, jet_pixel;
      Eigen::Matrix2d d_uv, jet_d_uv;
      Eigen::Matrix<double, 2, kNumParams, Eigen::RowMajor> d_params,
          jet_d_params;
      ProjectWithJacobians<CameraModel>(camera.ParamsData(), point.x(),
                                        point.y(), pixel.data(), &d_uv,
                                        d_params.data());
      camera_model_jacobians::ProjectWithJets<CameraModel, 2 + kNumParams>(
          camera.ParamsData(), point.x(), point.y(), jet_pixel.data(),
          &jet_d_uv, jet_d_params.data());
      const Eigen::Vector2d colmap_pixel = camera.WorldToImage(point);
      ASSERT_TRUE(pixel.allFinite() && d_uv.allFinite() &&
                  d_params.allFinite());
      EXPECT_LT((pixel - colmap_pixel).norm(), 1e-12 * colmap_pixel.norm());
      EXPECT_LT((pixel - jet_pixel).norm(), 1e-12 * jet_pixel.norm());
      EXPECT_LT((d_uv - jet_d_uv).norm(), 1e-10 * jet_d_uv.norm());
      EXPECT_LT((d_params - jet_d_params).norm(), 1e-10 * jet_d_params.norm());
      // Without the parameters' Jacobian the rest is the same.
      Eigen::Vector2d pixel_only;
      Eigen::Matrix2d d_uv_only;
      ProjectWithJacobians<CameraModel>(camera.ParamsData(), point.x(),
                                        point.y(), pixel_only.data(),
                                        &d_uv_only, nullptr);
      EXPECT_EQ(pixel_only, pixel);
      EXPECT_EQ(d_uv_only, d_uv);
    }
  }
}

TEST(CameraModelJacobians, ClosedFormMatchesJetsForTheCommonModels) {
  ExpectClosedFormMatchesJets<colmap::SimplePinholeCameraModel>();
  ExpectClosedFormMatchesJets<colmap::PinholeCameraModel>();
  ExpectClosedFormMatchesJets<colmap::SimpleRadialCameraModel>();
  ExpectClosedFormMatchesJets<colmap::RadialCameraModel>();
  ExpectClosedFormMatchesJets<colmap::OpenCVCameraModel>();
  ExpectClosedFormMatchesJets<colmap::FullOpenCVCameraModel>();
  ExpectClosedFormMatchesJets<colmap::OpenCVFisheyeCameraModel>();
}

// The finite differences of the pixel agree with the closed form: a check
// of the Jets' reference itself, independent of COLMAP's templates.
TEST(CameraModelJacobians, ClosedFormMatchesCentralDifferences) {
  using CameraModel = colmap::FullOpenCVCameraModel;
  constexpr int kNumParams = static_cast<int>(CameraModel::kNumParams);
  std::vector<double> params = {500,  520,   320,  240, 0.1,   -0.05,
                                0.01, -0.02, 0.03, 0.2, -0.04, 0.01};
  const Eigen::Vector2d point(0.4, -0.3);
  Eigen::Vector2d pixel;
  Eigen::Matrix2d d_uv;
  Eigen::Matrix<double, 2, kNumParams, Eigen::RowMajor> d_params;
  ProjectWithJacobians<CameraModel>(params.data(), point.x(), point.y(),
                                    pixel.data(), &d_uv, d_params.data());
  const auto pixel_at = [](const std::vector<double>& at_params,
                           const Eigen::Vector2d& at_point) {
    Eigen::Vector2d at_pixel;
    CameraModel::WorldToImage(at_params.data(), at_point.x(), at_point.y(),
                              &at_pixel.x(), &at_pixel.y());
    return at_pixel;
  };
  const double h = 1e-6;
  for (int k = 0; k < kNumParams; ++k) {
    std::vector<double> plus = params, minus = params;
    plus[k] += h;
    minus[k] -= h;
    const Eigen::Vector2d difference =
        (pixel_at(plus, point) - pixel_at(minus, point)) / (2 * h);
    EXPECT_LT((d_params.col(k) - difference).norm(), 1e-5) << k;
  }
  for (int k = 0; k < 2; ++k) {
    Eigen::Vector2d plus = point, minus = point;
    plus[k] += h;
    minus[k] -= h;
    const Eigen::Vector2d difference =
        (pixel_at(params, plus) - pixel_at(params, minus)) / (2 * h);
    EXPECT_LT((d_uv.col(k) - difference).norm(), 1e-4) << k;
  }
}

// The models without a closed form go through the Jets.
TEST(CameraModelJacobians, OtherModelsUseJets) {
  static_assert(!HasClosedFormJacobians<colmap::FOVCameraModel>());
  static_assert(!HasClosedFormJacobians<colmap::ThinPrismFisheyeCameraModel>());
  using CameraModel = colmap::FOVCameraModel;
  const double params[] = {500, 510, 320, 240, 0.8};
  Eigen::Vector2d pixel;
  Eigen::Matrix2d d_uv;
  double d_params[10];
  ProjectWithJacobians<CameraModel>(params, 0.3, -0.2, pixel.data(), &d_uv,
                                    d_params);
  double x, y;
  CameraModel::WorldToImage(params, 0.3, -0.2, &x, &y);
  EXPECT_DOUBLE_EQ(pixel.x(), x);
  EXPECT_DOUBLE_EQ(pixel.y(), y);
  EXPECT_DOUBLE_EQ(d_params[2], 1);      // dx/dcx
  EXPECT_DOUBLE_EQ(d_params[5 + 3], 1);  // dy/dcy
}

}  // namespace camera_model_jacobians_test
}  // namespace rig_calibrator
