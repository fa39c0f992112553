// The rolling-shutter projection of the capture model on exact data: points
// built on the ray of a chosen pixel at that pixel's row pose (the model's
// own construction) are projected back to that pixel, and the returned pixel
// reprojects with the pose of its own row; behind the camera, or with a
// shutter much slower than the motion, there is no pixel.
#include "src/synthetic/capture_model.h"

#include <colmap/base/camera_models.h>
#include <gtest/gtest.h>

#include <random>

#include "src/synthetic/rig_presets.h"

namespace rig_calibrator {
namespace capture_model_test {

// A rolling-shutter image of a fisheye helmet camera (cam2, looking back
// left) at 1.5 m/s and 60 degrees/s, 30 microseconds per row, 40 ms after the
// frameset time.
class RollingShutterProjectionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const PresetDefinition definition =
        MakePresetDefinition(RigPreset::kFisheyeHelmet5, 0);
    std::mt19937 rng(2);
    trajectory_.emplace(definition.motion, 1.5, 60, false, &rng);
    const RigGroundTruth truth = TruthOfDefinition(definition);
    camera_ = truth.cameras[2];
    capture_.trajectory = &*trajectory_;
    capture_.body_from_rig = BodyFromCamera(definition.cameras[0]);
    capture_.cam_from_rig = truth.cam_from_rig[2];
    capture_.top_row_time_s = 3.2 + 0.04;
    capture_.line_delay_s = 30e-6;
  }

  // The world point seen at pixel xy at `depth` along its ray, by the pose
  // of xy's row.
  Eigen::Vector3d PointAtPixel(const Eigen::Vector2d& xy, double depth) const {
    double u = 0, v = 0;
    colmap::CameraModelImageToWorld(camera_.ModelId(), camera_.Params(), xy.x(),
                                    xy.y(), &u, &v);
    const Rigid3d world_from_cam =
        capture_.CamFromWorldAt(capture_.RowTime(xy.y())).Inverse();
    return world_from_cam * (depth * Eigen::Vector3d(u, v, 1).normalized());
  }

  // |pi(cam_from_world(t(y)) X) - (x, y)|: the model's residual at a pixel.
  double RowPoseResidual(const Eigen::Vector2d& xy,
                         const Eigen::Vector3d& point) const {
    const Eigen::Vector3d in_camera =
        capture_.CamFromWorldAt(capture_.RowTime(xy.y())) * point;
    return (camera_.WorldToImage(in_camera.hnormalized()) - xy).norm();
  }

  std::optional<RigTrajectory> trajectory_;
  colmap::Camera camera_;
  ImageCapture capture_;
};

TEST_F(RollingShutterProjectionTest, RowTimesFollowTheDocumentedConvention) {
  EXPECT_DOUBLE_EQ(capture_.RowTime(0.5), 3.24);
  EXPECT_DOUBLE_EQ(capture_.RowTime(10.5), 3.24 + 10 * 30e-6);
  EXPECT_DOUBLE_EQ(capture_.RowTime(480), 3.24 + 479.5 * 30e-6);
}

// Exact data (built with the model's own row poses): the solver returns the
// pixel the point was built from (to 1e-9 px from its projection by that
// row's pose), and that pixel reprojects with its own row's pose to 1e-9 px; the global-shutter projection (every row at
// the top row's pose) is off by pixels, so the test sees the shutter.
TEST_F(RollingShutterProjectionTest, ExactPointsProjectToTheirPixel) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> x(1, camera_.Width() - 1);
  std::uniform_real_distribution<double> y(1, camera_.Height() - 1);
  std::uniform_real_distribution<double> depth(1.0, 10.0);
  double max_global_shutter_error = 0;
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector2d pixel(x(rng), y(rng));
    const Eigen::Vector3d point = PointAtPixel(pixel, depth(rng));
    Eigen::Vector2d projected;
    ASSERT_TRUE(ProjectWithRollingShutter(camera_, capture_, point, &projected))
        << pixel.transpose();
    // The pixel the point was built from, up to the camera model's own
    // round trip (COLMAP's iterative undistortion: ~1e-9 px for fisheye);
    // exactly its forward projection by the pixel's row pose.
    const Eigen::Vector3d in_row_camera =
        capture_.CamFromWorldAt(capture_.RowTime(pixel.y())) * point;
    const Eigen::Vector2d forward =
        camera_.WorldToImage(in_row_camera.hnormalized());
    EXPECT_LT((projected - pixel).norm(), 1e-7) << pixel.transpose();
    EXPECT_LT((projected - forward).norm(), 1e-9) << pixel.transpose();
    EXPECT_LT(RowPoseResidual(projected, point), 1e-9) << pixel.transpose();
    const Eigen::Vector3d in_top_row_camera =
        capture_.CamFromWorldAt(capture_.top_row_time_s) * point;
    max_global_shutter_error = std::max(
        max_global_shutter_error,
        (camera_.WorldToImage(in_top_row_camera.hnormalized()) - pixel)
            .norm());
  }
  EXPECT_GT(max_global_shutter_error, 2.0);
}

// No pixel for a point behind the camera, nor when the shutter is so slow
// (50 ms per row while the rig turns: the point moves by many rows per row
// of readout) that the iteration cannot converge.
TEST_F(RollingShutterProjectionTest, NoPixelBehindOrWithoutConvergence) {
  const Eigen::Vector2d pixel(320, 240);
  const Eigen::Vector3d in_front = PointAtPixel(pixel, 5.0);
  const Eigen::Vector3d camera_center =
      capture_.CamFromWorldAt(capture_.RowTime(pixel.y())).Center();
  const Eigen::Vector3d behind = camera_center - (in_front - camera_center);
  Eigen::Vector2d projected;
  EXPECT_FALSE(ProjectWithRollingShutter(camera_, capture_, behind, &projected));
  capture_.line_delay_s = 0.05;
  EXPECT_FALSE(
      ProjectWithRollingShutter(camera_, capture_, in_front, &projected));
}

}  // namespace capture_model_test
}  // namespace rig_calibrator
