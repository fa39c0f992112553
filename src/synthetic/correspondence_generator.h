// The map points and 2D-3D correspondences of synthetic rig images: new
// points at random pixels and depths (optionally on the ground plane), feature
// tracks re-observing recent points, wrong matches and pixel noise. Internal
// to the synthetic data generator (synthetic_rig.h).
#pragma once

#include <colmap/base/camera.h>

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <random>
#include <unordered_set>
#include <vector>

#include "src/geometry/rigid3d.h"
#include "src/synthetic/capture_model.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {

// A camera pose with what the generator derives from it.
struct CameraPose {
  CameraPose() = default;
  explicit CameraPose(const Rigid3d& cam_from_world);

  Rigid3d cam_from_world;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // in the world
  Eigen::Matrix3d world_from_cam_rotation = Eigen::Matrix3d::Identity();
};

// Everything the generator needs about one image.
struct ImageContext {
  const colmap::Camera* camera = nullptr;
  // The pose of every row (global shutter), or of the top row when the image
  // has a rolling shutter.
  CameraPose pose;
  // A rolling shutter (capture_model.h): every row at its own time and pose.
  std::optional<ImageCapture> rolling_shutter;
  // Pixel window holding the image's correspondences (feature_window).
  Eigen::Vector2d window_min = Eigen::Vector2d::Zero();
  Eigen::Vector2d window_max = Eigen::Vector2d::Zero();

  bool InWindow(const Eigen::Vector2d& xy) const {
    return xy.x() >= window_min.x() && xy.y() >= window_min.y() &&
           xy.x() <= window_max.x() && xy.y() <= window_max.y();
  }
  // The pose at which the row through pixel coordinate y is captured.
  CameraPose PoseOfRow(double y) const;
  // The point in the frame of the camera at the pose that observes it: the
  // image's pose, or with a rolling shutter the pose of the row of its pixel
  // (ProjectWithRollingShutter; false when that has no solution).
  bool PointInCamera(const Eigen::Vector3d& point_in_world,
                     Eigen::Vector3d* point_in_camera) const;
};

// The generator's state: the map points created so far, with the frameset
// that created them (non-decreasing), and the random engine.
class PointGenerator {
 public:
  PointGenerator(const SyntheticRigOptions& options, std::mt19937* rng)
      : options_(options), rng_(rng) {}

  // A new map point seen by the image at a random pixel (inside the image,
  // at a distance in [min_depth, max_depth]); on the ground plane with
  // probability near_planar_ratio when possible. False if none was found.
  bool NewVisiblePoint(const ImageContext& image, int frameset,
                       int64_t* point3D_id, Eigen::Vector2d* xy);

  // Up to `count` existing map points from recent framesets that the image
  // sees within the depth range, excluding `excluded` ids.
  void TrackPoints(const ImageContext& image, int frameset, int count,
                   std::vector<int64_t>* point3D_ids,
                   std::vector<Eigen::Vector2d>* xys);

  // A map point that is not among `excluded` and projects more than
  // kMinOutlierOffsetPx away from `xy` (or lies behind the camera): a recent
  // map point if one qualifies, else a new one in view.
  bool WrongPoint(const ImageContext& image, int frameset,
                  const Eigen::Vector2d& xy,
                  const std::unordered_set<int64_t>& excluded,
                  int64_t* point3D_id);

  const Eigen::Vector3d& Point(int64_t id) const { return points_[id]; }
  const std::vector<Eigen::Vector3d>& Points() const { return points_; }

 private:
  int64_t AddPoint(const Eigen::Vector3d& point, int frameset);

  // Ids of the points created by the last kTrackWindowFramesets framesets
  // and the current one.
  std::vector<int64_t> RecentPoints(int frameset) const;

  // Behind the camera, or projecting (wherever, even outside the image) far
  // from xy, with the pose of xy's row: the residual of the correspondence.
  bool IsWrongFor(const ImageContext& image, const Eigen::Vector3d& point,
                  const Eigen::Vector2d& xy) const;

  // The world direction of the ray through a uniformly random pixel, and
  // the pose of that pixel's row.
  bool RandomRay(const ImageContext& image, CameraPose* row_pose,
                 Eigen::Vector3d* ray_in_world);

  const SyntheticRigOptions& options_;
  std::mt19937* rng_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<int> point_framesets_;
};

// Adds Gaussian noise of standard deviation noise_px to each coordinate,
// redrawn until the point stays inside the image (xy itself after 100 draws
// outside, or for noise_px <= 0).
Eigen::Vector2d AddPixelNoise(const colmap::Camera& camera,
                              const Eigen::Vector2d& xy, double noise_px,
                              std::mt19937* rng);

}  // namespace rig_calibrator
