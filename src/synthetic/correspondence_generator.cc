#include "src/synthetic/correspondence_generator.h"

#include <colmap/base/camera_models.h>

#include <algorithm>
#include <cmath>

namespace rig_calibrator {
namespace {

// Wrong matches must be wrong by more than this (pixels).
constexpr double kMinOutlierOffsetPx = 20.0;
// Track points are searched among the points created by this many previous
// framesets (and the current one).
constexpr int kTrackWindowFramesets = 3;
// Random pixels drawn before giving up on one correspondence.
constexpr int kMaxSampleAttempts = 100;

bool IsInsideImage(const colmap::Camera& camera, const Eigen::Vector2d& xy) {
  return xy.x() >= 0 && xy.y() >= 0 && xy.x() <= camera.Width() &&
         xy.y() <= camera.Height();
}

// Projects a point given in the camera frame; false when it is behind the
// camera or outside the image, or when the model does not map the pixel back
// to the point's ray (beyond the model's valid field of view).
bool ProjectIntoImage(const colmap::Camera& camera,
                      const Eigen::Vector3d& point_in_camera,
                      Eigen::Vector2d* xy) {
  if (point_in_camera.z() <= 1e-9 * point_in_camera.norm()) {
    return false;
  }
  const double u = point_in_camera.x() / point_in_camera.z();
  const double v = point_in_camera.y() / point_in_camera.z();
  colmap::CameraModelWorldToImage(camera.ModelId(), camera.Params(), u, v,
                                  &xy->x(), &xy->y());
  if (!xy->allFinite() || !IsInsideImage(camera, *xy)) {
    return false;
  }
  double u_back = 0, v_back = 0;
  colmap::CameraModelImageToWorld(camera.ModelId(), camera.Params(), xy->x(),
                                  xy->y(), &u_back, &v_back);
  return std::isfinite(u_back) && std::isfinite(v_back) &&
         std::hypot(u_back - u, v_back - v) <= 1e-6 * (1 + std::hypot(u, v));
}

}  // namespace

CameraPose::CameraPose(const Rigid3d& cam_from_world)
    : cam_from_world(cam_from_world) {
  const Rigid3d world_from_cam = cam_from_world.Inverse();
  center = world_from_cam.translation;
  world_from_cam_rotation = world_from_cam.RotationMatrix();
}

CameraPose ImageContext::PoseOfRow(double y) const {
  if (!rolling_shutter) return pose;
  return CameraPose(
      rolling_shutter->CamFromWorldAt(rolling_shutter->RowTime(y)));
}

bool ImageContext::PointInCamera(const Eigen::Vector3d& point_in_world,
                                 Eigen::Vector3d* point_in_camera) const {
  if (!rolling_shutter) {
    *point_in_camera = pose.cam_from_world * point_in_world;
    return true;
  }
  Eigen::Vector2d xy;
  if (!ProjectWithRollingShutter(*camera, *rolling_shutter, point_in_world,
                                 &xy)) {
    return false;
  }
  *point_in_camera = rolling_shutter->CamFromWorldAt(
                         rolling_shutter->RowTime(xy.y())) *
                     point_in_world;
  return true;
}

bool PointGenerator::NewVisiblePoint(const ImageContext& image, int frameset,
                                     int64_t* point3D_id, Eigen::Vector2d* xy) {
  std::uniform_real_distribution<double> unit(0, 1);
  const bool on_plane = unit(*rng_) < options_.near_planar_ratio;
  for (int attempt = 0; attempt < kMaxSampleAttempts; ++attempt) {
    CameraPose row_pose;
    Eigen::Vector3d ray_in_world;
    if (!RandomRay(image, &row_pose, &ray_in_world)) {
      continue;
    }
    double distance = 0;
    if (on_plane && attempt < kMaxSampleAttempts / 2) {
      // Ground z = 0: center.z + distance * ray.z = 0.
      if (ray_in_world.z() >= -1e-9) {
        continue;
      }
      distance = -row_pose.center.z() / ray_in_world.z();
      if (distance < options_.min_depth || distance > options_.max_depth) {
        continue;
      }
    } else {
      distance = std::uniform_real_distribution<double>(
          options_.min_depth, options_.max_depth)(*rng_);
    }
    const Eigen::Vector3d point = row_pose.center + distance * ray_in_world;
    // With a rolling shutter the point is on the ray of its pixel at that
    // row's pose, so this projection (by the same pose) is the fixed point
    // of capture_model.h up to rounding.
    if (!ProjectIntoImage(*image.camera, row_pose.cam_from_world * point,
                          xy) ||
        !image.InWindow(*xy)) {
      continue;
    }
    *point3D_id = AddPoint(point, frameset);
    return true;
  }
  return false;
}

void PointGenerator::TrackPoints(const ImageContext& image, int frameset,
                                 int count, std::vector<int64_t>* point3D_ids,
                                 std::vector<Eigen::Vector2d>* xys) {
  std::vector<int64_t> candidates = RecentPoints(frameset);
  std::shuffle(candidates.begin(), candidates.end(), *rng_);
  for (const int64_t id : candidates) {
    if (static_cast<int>(point3D_ids->size()) >= count) {
      break;
    }
    Eigen::Vector3d point_in_camera;
    if (!image.PointInCamera(points_[id], &point_in_camera)) {
      continue;
    }
    const double distance = point_in_camera.norm();
    Eigen::Vector2d xy;
    if (distance < options_.min_depth || distance > options_.max_depth ||
        !ProjectIntoImage(*image.camera, point_in_camera, &xy) ||
        !image.InWindow(xy)) {
      continue;
    }
    point3D_ids->push_back(id);
    xys->push_back(xy);
  }
}

bool PointGenerator::WrongPoint(const ImageContext& image, int frameset,
                                const Eigen::Vector2d& xy,
                                const std::unordered_set<int64_t>& excluded,
                                int64_t* point3D_id) {
  const std::vector<int64_t> candidates = RecentPoints(frameset);
  if (!candidates.empty()) {
    std::uniform_int_distribution<size_t> pick(0, candidates.size() - 1);
    for (int attempt = 0; attempt < 20; ++attempt) {
      const int64_t id = candidates[pick(*rng_)];
      if (excluded.count(id) == 0 && IsWrongFor(image, points_[id], xy)) {
        *point3D_id = id;
        return true;
      }
    }
  }
  for (int attempt = 0; attempt < kMaxSampleAttempts; ++attempt) {
    Eigen::Vector2d other_xy;
    if (NewVisiblePoint(image, frameset, point3D_id, &other_xy) &&
        (other_xy - xy).norm() > kMinOutlierOffsetPx) {
      return true;
    }
  }
  return false;
}

int64_t PointGenerator::AddPoint(const Eigen::Vector3d& point, int frameset) {
  points_.push_back(point);
  point_framesets_.push_back(frameset);
  return static_cast<int64_t>(points_.size()) - 1;
}

std::vector<int64_t> PointGenerator::RecentPoints(int frameset) const {
  const auto first =
      std::lower_bound(point_framesets_.begin(), point_framesets_.end(),
                       frameset - kTrackWindowFramesets);
  std::vector<int64_t> ids;
  for (int64_t id = first - point_framesets_.begin();
       id < static_cast<int64_t>(points_.size()); ++id) {
    ids.push_back(id);
  }
  return ids;
}

bool PointGenerator::IsWrongFor(const ImageContext& image,
                                const Eigen::Vector3d& point,
                                const Eigen::Vector2d& xy) const {
  const Eigen::Vector3d point_in_camera =
      image.PoseOfRow(xy.y()).cam_from_world * point;
  if (point_in_camera.z() <= 0) {
    return true;
  }
  const Eigen::Vector2d projected =
      image.camera->WorldToImage(point_in_camera.hnormalized());
  return !projected.allFinite() ||
         (projected - xy).norm() > kMinOutlierOffsetPx;
}

bool PointGenerator::RandomRay(const ImageContext& image,
                               CameraPose* row_pose,
                               Eigen::Vector3d* ray_in_world) {
  const colmap::Camera& camera = *image.camera;
  const double x = std::uniform_real_distribution<double>(
      image.window_min.x(), image.window_max.x())(*rng_);
  const double y = std::uniform_real_distribution<double>(
      image.window_min.y(), image.window_max.y())(*rng_);
  double u = 0, v = 0;
  colmap::CameraModelImageToWorld(camera.ModelId(), camera.Params(), x, y, &u,
                                  &v);
  if (!std::isfinite(u) || !std::isfinite(v)) {
    return false;
  }
  *row_pose = image.PoseOfRow(y);
  *ray_in_world = row_pose->world_from_cam_rotation *
                  Eigen::Vector3d(u, v, 1).normalized();
  return true;
}

Eigen::Vector2d AddPixelNoise(const colmap::Camera& camera,
                              const Eigen::Vector2d& xy, double noise_px,
                              std::mt19937* rng) {
  if (noise_px <= 0) {
    return xy;
  }
  std::normal_distribution<double> noise(0, noise_px);
  for (int attempt = 0; attempt < kMaxSampleAttempts; ++attempt) {
    const Eigen::Vector2d noisy(xy.x() + noise(*rng), xy.y() + noise(*rng));
    if (IsInsideImage(camera, noisy)) {
      return noisy;
    }
  }
  return xy;
}

}  // namespace rig_calibrator
