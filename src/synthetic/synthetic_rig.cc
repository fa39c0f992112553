#include "src/synthetic/synthetic_rig.h"

#include <colmap/base/camera_models.h>
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>
#include <unordered_set>
#include <utility>

namespace rig_calibrator {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

// Wrong matches must be wrong by more than this (pixels).
constexpr double kMinOutlierOffsetPx = 20.0;
// Track points are searched among the points created by this many previous
// framesets (and the current one).
constexpr int kTrackWindowFramesets = 3;
// Random pixels drawn before giving up on one correspondence.
constexpr int kMaxSampleAttempts = 100;
// Most cameras of a ring (ring_num_cameras): 10 degrees apart.
constexpr int kMaxRingCameras = 36;

// One camera of a preset, placed in the body frame (x forward, y left, z up).
struct CameraSpec {
  std::string model_name;
  int width = 0;
  int height = 0;
  std::vector<double> params;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // in the body frame
  double yaw_deg = 0;    // viewing direction about z, 0 = forward, 90 = left
  double pitch_deg = 0;  // positive = looking up
  double roll_deg = 0;   // about the viewing direction
};

// How the rig moves: a walk or a drive with sinusoidal yaw, pitch and roll
// around a slowly turning heading (phases are drawn from the seed).
struct MotionProfile {
  double step_m = 0.4;    // distance between framesets
  double height_m = 1.6;  // body origin above the ground
  double bob_m = 0.03;
  double yaw_amplitude_deg = 40, yaw_period = 25, yaw_rate_deg = 3;
  double pitch_amplitude_deg = 8, pitch_period = 17;
  double roll_amplitude_deg = 6, roll_period = 13;
};

struct PresetDefinition {
  std::vector<CameraSpec> cameras;
  MotionProfile motion;
};

// body_from_cam for a camera looking along (yaw, pitch) with a roll about its
// viewing direction. Camera axes: x right, y down, z forward.
Rigid3d BodyFromCamera(const CameraSpec& spec) {
  const double yaw = spec.yaw_deg * kDegToRad;
  const double pitch = spec.pitch_deg * kDegToRad;
  const double roll = spec.roll_deg * kDegToRad;
  const Eigen::Vector3d forward(std::cos(pitch) * std::cos(yaw),
                                std::cos(pitch) * std::sin(yaw),
                                std::sin(pitch));
  const Eigen::Vector3d right0 =
      forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down0 = forward.cross(right0);
  Eigen::Matrix3d body_from_cam_rotation;
  body_from_cam_rotation.col(0) =
      std::cos(roll) * right0 + std::sin(roll) * down0;
  body_from_cam_rotation.col(1) =
      -std::sin(roll) * right0 + std::cos(roll) * down0;
  body_from_cam_rotation.col(2) = forward;
  return Rigid3d(body_from_cam_rotation, spec.position);
}

// Cameras evenly spaced on a horizontal ring, looking outwards.
void PlaceOnRing(double radius, std::vector<CameraSpec>* cameras) {
  const int num_cameras = cameras->size();
  for (int i = 0; i < num_cameras; ++i) {
    const double yaw_deg = 360.0 * i / num_cameras;
    CameraSpec& spec = (*cameras)[i];
    spec.yaw_deg = yaw_deg;
    spec.position.x() = radius * std::cos(yaw_deg * kDegToRad);
    spec.position.y() = radius * std::sin(yaw_deg * kDegToRad);
  }
}

// ring5, or its layout with num_cameras cameras (ring_num_cameras): camera i
// takes the parameters of ring5's camera i mod 5, its focal lengths scaled by
// 1 + 0.03 * (i / 5) so that no two cameras are alike.
PresetDefinition Ring(int num_cameras) {
  PresetDefinition preset;
  // fx, fy, cx, cy, k1, k2, p1, p2; principal points off the center
  // (320, 240) by up to 20 px in varied directions.
  const std::vector<std::vector<double>> params = {
      {420, 421, 332, 232, -0.30, 0.080, 4e-4, -3e-4},
      {445, 444, 302, 245, -0.32, 0.070, -5e-4, 2e-4},
      {405, 406, 324, 255, -0.28, 0.090, 2e-4, 5e-4},
      {432, 433, 313, 221, -0.31, 0.085, -3e-4, -4e-4},
      {412, 411, 339, 250, -0.29, 0.075, 5e-4, 1e-4}};
  const double pitch_deg[] = {2, -3, 1, -2, 3};
  const double roll_deg[] = {0, 1, -1, 0.5, -0.5};
  const double height_m[] = {0, 0.01, -0.005, 0.008, -0.01};
  for (int i = 0; i < num_cameras; ++i) {
    CameraSpec spec;
    spec.model_name = "OPENCV";
    spec.width = 640;
    spec.height = 480;
    spec.params = params[i % 5];
    spec.params[0] *= 1 + 0.03 * (i / 5);
    spec.params[1] *= 1 + 0.03 * (i / 5);
    spec.pitch_deg = pitch_deg[i % 5];
    spec.roll_deg = roll_deg[i % 5];
    spec.position.z() = height_m[i % 5];
    preset.cameras.push_back(spec);
  }
  PlaceOnRing(0.15, &preset.cameras);
  preset.motion.height_m = 1.5;
  return preset;
}

// OPENCV_FISHEYE focal length that maps the given diagonal field of view
// onto the image diagonal: half_diagonal = f * theta_d(half_fov).
double FisheyeFocalForDiagonalFov(int width, int height, double fov_deg,
                                  const double* k) {
  const double theta = 0.5 * fov_deg * kDegToRad;
  const double theta2 = theta * theta;
  const double theta_d =
      theta *
      (1 + theta2 * (k[0] + theta2 * (k[1] + theta2 * (k[2] + theta2 * k[3]))));
  return 0.5 * std::hypot(width, height) / theta_d;
}

CameraSpec FisheyeCamera(int width, int height, double fov_deg,
                         const std::vector<double>& k, double fy_ratio,
                         double cx_offset, double cy_offset) {
  CameraSpec spec;
  spec.model_name = "OPENCV_FISHEYE";
  spec.width = width;
  spec.height = height;
  const double f = FisheyeFocalForDiagonalFov(width, height, fov_deg, k.data());
  spec.params = {f,
                 f * fy_ratio,
                 0.5 * width + cx_offset,
                 0.5 * height + cy_offset,
                 k[0],
                 k[1],
                 k[2],
                 k[3]};
  return spec;
}

PresetDefinition FisheyeHelmet5() {
  PresetDefinition preset;
  const double fov_deg[] = {150, 145, 155, 148, 152};
  const std::vector<std::vector<double>> k = {{0.020, -0.010, 0.003, -0.0005},
                                              {0.030, -0.012, 0.002, -0.0004},
                                              {0.015, -0.008, 0.004, -0.0006},
                                              {0.025, -0.011, 0.001, -0.0003},
                                              {0.018, -0.009, 0.003, -0.0005}};
  const double fy_ratio[] = {1.0, 1.001, 0.999, 1.0005, 0.9995};
  const double cx_offset[] = {6, -8, 3, -4, 9};
  const double cy_offset[] = {-5, 4, 8, -9, 2};
  const double pitch_deg[] = {15, -10, 12, -15, 10};
  for (int i = 0; i < 5; ++i) {
    CameraSpec spec = FisheyeCamera(640, 480, fov_deg[i], k[i], fy_ratio[i],
                                    cx_offset[i], cy_offset[i]);
    spec.pitch_deg = pitch_deg[i];
    spec.roll_deg = (i % 2 == 0 ? 1.5 : -1.0);
    spec.position.z() = 0.02 * std::sin(i);
    preset.cameras.push_back(spec);
  }
  PlaceOnRing(0.12, &preset.cameras);
  preset.motion.height_m = 1.7;
  return preset;
}

PresetDefinition CarSurround4() {
  PresetDefinition preset;
  // The body origin is on the ground below the car's center; the car is
  // 4.5 m long and 1.8 m wide.
  CameraSpec front;
  front.model_name = "OPENCV";
  front.width = 960;
  front.height = 600;
  front.params = {420, 420.5, 488, 293, -0.25, 0.06, 3e-4, -2e-4};
  front.position = Eigen::Vector3d(2.25, 0.0, 0.6);
  front.pitch_deg = -12;

  const std::vector<double> k_left = {0.030, -0.010, 0.002, -0.0004};
  CameraSpec left = FisheyeCamera(800, 600, 160, k_left, 1.0, -7, 5);
  left.position = Eigen::Vector3d(0.9, 0.9, 1.0);
  left.yaw_deg = 90;
  left.pitch_deg = -30;

  CameraSpec back;
  back.model_name = "RADIAL";
  back.width = 640;
  back.height = 480;
  back.params = {380, 326, 236, -0.20, 0.04};
  back.position = Eigen::Vector3d(-2.25, 0.0, 1.1);
  back.yaw_deg = 180;
  back.pitch_deg = -20;

  const std::vector<double> k_right = {0.020, -0.008, 0.003, -0.0005};
  CameraSpec right = FisheyeCamera(800, 600, 160, k_right, 1.0005, 9, -6);
  right.position = Eigen::Vector3d(0.9, -0.9, 1.0);
  right.yaw_deg = -90;
  right.pitch_deg = -28;

  preset.cameras = {front, left, back, right};
  preset.motion.step_m = 1.5;
  preset.motion.height_m = 0;
  preset.motion.bob_m = 0.01;
  preset.motion.yaw_amplitude_deg = 30;
  preset.motion.yaw_period = 40;
  preset.motion.yaw_rate_deg = 1.5;
  preset.motion.pitch_amplitude_deg = 2;
  preset.motion.roll_amplitude_deg = 2;
  return preset;
}

PresetDefinition StereoPair() {
  PresetDefinition preset;
  // EuRoC MAV cam0/cam1 intrinsics (OPENCV = pinhole + radtan).
  CameraSpec left;
  left.model_name = "OPENCV";
  left.width = 752;
  left.height = 480;
  left.params = {458.654,     457.296,    367.215,    248.375,
                 -0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
  CameraSpec right = left;
  right.params = {457.587,     456.134,    379.999,     255.238,
                  -0.28368365, 0.07451284, -0.00010473, -3.55590700e-05};
  // 0.11 m to the right (-y in the body frame), nearly parallel axes.
  right.position = Eigen::Vector3d(0.0005, -0.11, 0.0008);
  right.yaw_deg = 0.1;
  right.pitch_deg = -0.15;
  right.roll_deg = 0.05;
  preset.cameras = {left, right};
  preset.motion.height_m = 1.2;
  return preset;
}

PresetDefinition MakePresetDefinition(RigPreset preset) {
  switch (preset) {
    case RigPreset::kRing5:
      return Ring(5);
    case RigPreset::kFisheyeHelmet5:
      return FisheyeHelmet5();
    case RigPreset::kCarSurround4:
      return CarSurround4();
    case RigPreset::kStereoPair:
      return StereoPair();
  }
  return Ring(5);
}

PresetDefinition MakePresetDefinition(const SyntheticRigOptions& options) {
  if (options.preset == RigPreset::kRing5 && options.ring_num_cameras > 0) {
    return Ring(options.ring_num_cameras);
  }
  return MakePresetDefinition(options.preset);
}

colmap::Camera MakeCamera(const std::string& model_name, int width, int height,
                          const std::vector<double>& params, int camera_id) {
  colmap::Camera camera;
  camera.SetCameraId(camera_id);
  camera.SetModelIdFromName(model_name);
  camera.SetWidth(width);
  camera.SetHeight(height);
  camera.SetParams(params);
  return camera;
}

// world_from_body along the trajectory, frameset by frameset. The heading
// turns slowly (yaw_rate) while yaw, pitch and roll oscillate, so the rig
// sees the map under varied rotations.
std::vector<Rigid3d> MakeTrajectory(const MotionProfile& motion,
                                    int num_framesets, std::mt19937* rng) {
  std::uniform_real_distribution<double> phase_distribution(0, 2 * M_PI);
  const double yaw_phase = phase_distribution(*rng);
  const double pitch_phase = phase_distribution(*rng);
  const double roll_phase = phase_distribution(*rng);
  const double bob_phase = phase_distribution(*rng);
  std::vector<Rigid3d> world_from_body;
  Eigen::Vector3d position(0, 0, motion.height_m);
  for (int j = 0; j < num_framesets; ++j) {
    const double yaw =
        (motion.yaw_amplitude_deg *
             std::sin(2 * M_PI * j / motion.yaw_period + yaw_phase) +
         motion.yaw_rate_deg * j) *
        kDegToRad;
    const double pitch =
        motion.pitch_amplitude_deg *
        std::sin(2 * M_PI * j / motion.pitch_period + pitch_phase) * kDegToRad;
    const double roll =
        motion.roll_amplitude_deg *
        std::sin(2 * M_PI * j / motion.roll_period + roll_phase) * kDegToRad;
    if (j > 0) {
      position.x() += motion.step_m * std::cos(yaw);
      position.y() += motion.step_m * std::sin(yaw);
    }
    position.z() = motion.height_m +
                   motion.bob_m * std::sin(2 * M_PI * j / 2.0 + bob_phase);
    // Body y is left and z up, so a positive pitch (nose up) is a negative
    // rotation about y.
    const Eigen::Matrix3d rotation =
        (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(-pitch, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
    world_from_body.emplace_back(rotation, position);
  }
  return world_from_body;
}

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

// Everything the generator needs about one image.
struct ImageContext {
  const colmap::Camera* camera = nullptr;
  Rigid3d cam_from_world;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // in the world
  Eigen::Matrix3d world_from_cam_rotation = Eigen::Matrix3d::Identity();
  // Pixel window holding the image's correspondences (feature_window).
  Eigen::Vector2d window_min = Eigen::Vector2d::Zero();
  Eigen::Vector2d window_max = Eigen::Vector2d::Zero();

  bool InWindow(const Eigen::Vector2d& xy) const {
    return xy.x() >= window_min.x() && xy.y() >= window_min.y() &&
           xy.x() <= window_max.x() && xy.y() <= window_max.y();
  }
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
                       int64_t* point3D_id, Eigen::Vector2d* xy) {
    std::uniform_real_distribution<double> unit(0, 1);
    const bool on_plane = unit(*rng_) < options_.near_planar_ratio;
    for (int attempt = 0; attempt < kMaxSampleAttempts; ++attempt) {
      Eigen::Vector3d ray_in_world;
      if (!RandomRay(image, &ray_in_world)) {
        continue;
      }
      double distance = 0;
      if (on_plane && attempt < kMaxSampleAttempts / 2) {
        // Ground z = 0: center.z + distance * ray.z = 0.
        if (ray_in_world.z() >= -1e-9) {
          continue;
        }
        distance = -image.center.z() / ray_in_world.z();
        if (distance < options_.min_depth || distance > options_.max_depth) {
          continue;
        }
      } else {
        distance = std::uniform_real_distribution<double>(
            options_.min_depth, options_.max_depth)(*rng_);
      }
      const Eigen::Vector3d point = image.center + distance * ray_in_world;
      if (!ProjectIntoImage(*image.camera, image.cam_from_world * point, xy) ||
          !image.InWindow(*xy)) {
        continue;
      }
      *point3D_id = AddPoint(point, frameset);
      return true;
    }
    return false;
  }

  // Up to `count` existing map points from recent framesets that the image
  // sees within the depth range, excluding `excluded` ids.
  void TrackPoints(const ImageContext& image, int frameset, int count,
                   std::vector<int64_t>* point3D_ids,
                   std::vector<Eigen::Vector2d>* xys) {
    std::vector<int64_t> candidates = RecentPoints(frameset);
    std::shuffle(candidates.begin(), candidates.end(), *rng_);
    for (const int64_t id : candidates) {
      if (static_cast<int>(point3D_ids->size()) >= count) {
        break;
      }
      const Eigen::Vector3d point_in_camera =
          image.cam_from_world * points_[id];
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

  // A map point that is not among `excluded` and projects more than
  // kMinOutlierOffsetPx away from `xy` (or lies behind the camera): a recent
  // map point if one qualifies, else a new one in view.
  bool WrongPoint(const ImageContext& image, int frameset,
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

  const Eigen::Vector3d& Point(int64_t id) const { return points_[id]; }

 private:
  int64_t AddPoint(const Eigen::Vector3d& point, int frameset) {
    points_.push_back(point);
    point_framesets_.push_back(frameset);
    return static_cast<int64_t>(points_.size()) - 1;
  }

  // Ids of the points created by the last kTrackWindowFramesets framesets
  // and the current one.
  std::vector<int64_t> RecentPoints(int frameset) const {
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

  // Behind the camera, or projecting (wherever, even outside the image) far
  // from xy.
  bool IsWrongFor(const ImageContext& image, const Eigen::Vector3d& point,
                  const Eigen::Vector2d& xy) const {
    const Eigen::Vector3d point_in_camera = image.cam_from_world * point;
    if (point_in_camera.z() <= 0) {
      return true;
    }
    const Eigen::Vector2d projected =
        image.camera->WorldToImage(point_in_camera.hnormalized());
    return !projected.allFinite() ||
           (projected - xy).norm() > kMinOutlierOffsetPx;
  }

  // The world direction of the ray through a uniformly random pixel.
  bool RandomRay(const ImageContext& image, Eigen::Vector3d* ray_in_world) {
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
    *ray_in_world =
        image.world_from_cam_rotation * Eigen::Vector3d(u, v, 1).normalized();
    return true;
  }

  const SyntheticRigOptions& options_;
  std::mt19937* rng_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<int> point_framesets_;
};

// Adds Gaussian noise, redrawn until the point stays inside the image.
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

// Which (frameset, camera) images exist: round(ratio * total) images are
// dropped at random, skipping drops that would empty a frameset.
std::vector<std::vector<char>> ChooseExistingImages(int num_framesets,
                                                    int num_cameras,
                                                    double missing_ratio,
                                                    std::mt19937* rng) {
  std::vector<std::vector<char>> exists(num_framesets,
                                        std::vector<char>(num_cameras, 1));
  std::vector<std::pair<int, int>> images;
  for (int j = 0; j < num_framesets; ++j) {
    for (int c = 0; c < num_cameras; ++c) {
      images.emplace_back(j, c);
    }
  }
  std::shuffle(images.begin(), images.end(), *rng);
  const int num_to_drop =
      static_cast<int>(std::lround(missing_ratio * images.size()));
  std::vector<int> remaining(num_framesets, num_cameras);
  int num_dropped = 0;
  for (const auto& [frameset, camera] : images) {
    if (num_dropped == num_to_drop) {
      break;
    }
    if (remaining[frameset] > 1) {
      exists[frameset][camera] = 0;
      --remaining[frameset];
      ++num_dropped;
    }
  }
  return exists;
}

std::string FramesetName(int frameset) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d", frameset);
  return name;
}

// The true cameras and extrinsics of a rig definition (no rig poses).
RigGroundTruth TruthOfDefinition(const PresetDefinition& definition) {
  RigGroundTruth truth;
  const Rigid3d body_from_rig = BodyFromCamera(definition.cameras[0]);
  for (size_t i = 0; i < definition.cameras.size(); ++i) {
    const CameraSpec& spec = definition.cameras[i];
    truth.cameras.push_back(MakeCamera(spec.model_name, spec.width, spec.height,
                                       spec.params, i + 1));
    truth.cam_from_rig.push_back(
        i == 0 ? Rigid3d() : BodyFromCamera(spec).Inverse() * body_from_rig);
    truth.camera_names.push_back("cam" + std::to_string(i));
  }
  return truth;
}

}  // namespace

bool RigPresetFromName(const std::string& name, RigPreset* preset) {
  for (const RigPreset candidate : AllRigPresets()) {
    if (RigPresetName(candidate) == name) {
      *preset = candidate;
      return true;
    }
  }
  return false;
}

std::string RigPresetName(RigPreset preset) {
  switch (preset) {
    case RigPreset::kRing5:
      return "ring5";
    case RigPreset::kFisheyeHelmet5:
      return "fisheye_helmet5";
    case RigPreset::kCarSurround4:
      return "car_surround4";
    case RigPreset::kStereoPair:
      return "stereo_pair";
  }
  return "unknown";
}

std::vector<RigPreset> AllRigPresets() {
  return {RigPreset::kRing5, RigPreset::kFisheyeHelmet5,
          RigPreset::kCarSurround4, RigPreset::kStereoPair};
}

RigGroundTruth MakeRigPreset(RigPreset preset) {
  return TruthOfDefinition(MakePresetDefinition(preset));
}

bool SyntheticRigOptions::Check(std::string* error) const {
  std::ostringstream message;
  if (num_framesets < 1) {
    message << "num_framesets must be >= 1, got " << num_framesets;
  } else if (points_per_image < 0) {
    message << "points_per_image must be >= 0, got " << points_per_image;
  } else if (!(noise_px >= 0)) {
    message << "noise_px must be >= 0, got " << noise_px;
  } else if (!(outlier_ratio >= 0 && outlier_ratio <= 1)) {
    message << "outlier_ratio must be in [0, 1], got " << outlier_ratio;
  } else if (!(missing_image_ratio >= 0 && missing_image_ratio < 1)) {
    message << "missing_image_ratio must be in [0, 1), got "
            << missing_image_ratio;
  } else if (!(min_depth > 0 && max_depth >= min_depth)) {
    message << "need 0 < min_depth <= max_depth, got " << min_depth << ", "
            << max_depth;
  } else if (!(near_planar_ratio >= 0 && near_planar_ratio <= 1)) {
    message << "near_planar_ratio must be in [0, 1], got " << near_planar_ratio;
  } else if (!(track_ratio >= 0 && track_ratio <= 1)) {
    message << "track_ratio must be in [0, 1], got " << track_ratio;
  } else if (ring_num_cameras != 0 &&
             (preset != RigPreset::kRing5 || ring_num_cameras < 2 ||
              ring_num_cameras > kMaxRingCameras)) {
    message << "ring_num_cameras must be 0, or 2.." << kMaxRingCameras
            << " with the ring5 preset, got " << ring_num_cameras << " with "
            << RigPresetName(preset);
  } else if (!(feature_window > 0 && feature_window <= 1)) {
    message << "feature_window must be in (0, 1], got " << feature_window;
  } else {
    return true;
  }
  *error = message.str();
  return false;
}

SyntheticRig GenerateSyntheticRig(const SyntheticRigOptions& options) {
  SyntheticRig rig;
  std::string error;
  if (!options.Check(&error)) {
    LOG(ERROR) << "Invalid synthetic rig options: " << error;
    return rig;
  }
  std::mt19937 rng(options.seed);
  const PresetDefinition definition = MakePresetDefinition(options);
  rig.truth = TruthOfDefinition(definition);
  const int num_cameras = rig.truth.cameras.size();

  const Rigid3d body_from_rig = BodyFromCamera(definition.cameras[0]);
  for (const Rigid3d& world_from_body :
       MakeTrajectory(definition.motion, options.num_framesets, &rng)) {
    rig.truth.rig_from_world.push_back(
        (world_from_body * body_from_rig).Inverse());
  }

  for (int c = 0; c < num_cameras; ++c) {
    const colmap::Camera& true_camera = rig.truth.cameras[c];
    RigCamera camera;
    camera.name = rig.truth.camera_names[c];
    camera.camera = true_camera;
    camera.camera.SetParams(colmap::CameraModelInitializeParams(
        true_camera.ModelId(),
        1.2 * std::max(true_camera.Width(), true_camera.Height()),
        true_camera.Width(), true_camera.Height()));
    rig.dataset.cameras.push_back(camera);
  }
  for (int j = 0; j < options.num_framesets; ++j) {
    rig.dataset.frameset_names.push_back(FramesetName(j));
  }
  rig.dataset.reference_camera = 0;

  const std::vector<std::vector<char>> image_exists = ChooseExistingImages(
      options.num_framesets, num_cameras, options.missing_image_ratio, &rng);
  const int num_outliers = static_cast<int>(
      std::lround(options.outlier_ratio * options.points_per_image));
  const int num_inliers = options.points_per_image - num_outliers;
  const int num_track_points =
      static_cast<int>(std::lround(options.track_ratio * num_inliers));

  PointGenerator generator(options, &rng);
  for (int j = 0; j < options.num_framesets; ++j) {
    for (int c = 0; c < num_cameras; ++c) {
      if (!image_exists[j][c]) {
        continue;
      }
      ImageContext context;
      context.camera = &rig.truth.cameras[c];
      context.cam_from_world =
          rig.truth.cam_from_rig[c] * rig.truth.rig_from_world[j];
      const Rigid3d world_from_cam = context.cam_from_world.Inverse();
      context.center = world_from_cam.translation;
      context.world_from_cam_rotation = world_from_cam.RotationMatrix();
      const Eigen::Vector2d size(context.camera->Width(),
                                 context.camera->Height());
      context.window_max = size;
      if (options.feature_window < 1) {
        // Drawn only for partial windows, so that whole-image datasets stay
        // those of earlier versions for the same seed.
        const Eigen::Vector2d window = options.feature_window * size;
        std::uniform_real_distribution<double> unit(0, 1);
        context.window_min.x() = unit(rng) * (size.x() - window.x());
        context.window_min.y() = unit(rng) * (size.y() - window.y());
        context.window_max = context.window_min + window;
      }

      std::vector<int64_t> ids;
      std::vector<Eigen::Vector2d> xys;
      generator.TrackPoints(context, j, num_track_points, &ids, &xys);
      while (static_cast<int>(ids.size()) < options.points_per_image) {
        int64_t id = -1;
        Eigen::Vector2d xy;
        if (!generator.NewVisiblePoint(context, j, &id, &xy)) {
          break;
        }
        ids.push_back(id);
        xys.push_back(xy);
      }
      if (static_cast<int>(ids.size()) < options.points_per_image) {
        LOG(WARNING) << "Image " << c << "/" << j << " got only " << ids.size()
                     << " of " << options.points_per_image << " points";
      }

      // The last num_outliers correspondences keep their 2D point but are
      // matched to a wrong map point; the order is shuffled afterwards.
      std::unordered_set<int64_t> observed(ids.begin(), ids.end());
      std::vector<char> is_outlier(ids.size(), 0);
      for (size_t k =
               std::max<int>(0, static_cast<int>(ids.size()) - num_outliers);
           k < ids.size(); ++k) {
        int64_t wrong_id = -1;
        if (generator.WrongPoint(context, j, xys[k], observed, &wrong_id)) {
          ids[k] = wrong_id;
          observed.insert(wrong_id);
          is_outlier[k] = 1;
        }
      }
      std::vector<int> order(ids.size());
      for (size_t k = 0; k < order.size(); ++k) {
        order[k] = k;
      }
      std::shuffle(order.begin(), order.end(), rng);

      RigImage image;
      image.name = rig.truth.camera_names[c] + "/" + FramesetName(j) + ".png";
      image.camera_index = c;
      image.frameset_index = j;
      std::vector<char> shuffled_is_outlier;
      for (const int k : order) {
        Correspondence correspondence;
        correspondence.point2D =
            AddPixelNoise(*context.camera, xys[k], options.noise_px, &rng);
        correspondence.point3D = generator.Point(ids[k]);
        correspondence.point3D_id = ids[k];
        image.correspondences.push_back(correspondence);
        shuffled_is_outlier.push_back(is_outlier[k]);
      }
      rig.dataset.images.push_back(std::move(image));
      rig.is_outlier.push_back(std::move(shuffled_is_outlier));
    }
  }
  return rig;
}

SyntheticRig SelectFramesets(const SyntheticRig& rig,
                             const std::vector<int>& framesets) {
  SyntheticRig selected;
  selected.dataset.cameras = rig.dataset.cameras;
  selected.dataset.reference_camera = rig.dataset.reference_camera;
  selected.truth = rig.truth;
  selected.truth.rig_from_world.clear();
  const int num_framesets = rig.dataset.frameset_names.size();
  std::vector<int> new_index(num_framesets, -1);
  for (const int frameset : framesets) {
    if (frameset < 0 || frameset >= num_framesets || new_index[frameset] >= 0) {
      LOG(ERROR) << "Skipping frameset index " << frameset
                 << " (out of range or repeated; the rig has " << num_framesets
                 << " framesets)";
      continue;
    }
    new_index[frameset] = selected.dataset.frameset_names.size();
    selected.dataset.frameset_names.push_back(
        rig.dataset.frameset_names[frameset]);
    selected.truth.rig_from_world.push_back(rig.truth.rig_from_world[frameset]);
  }
  // Images in the order of the selected framesets, cameras in order within.
  std::vector<std::vector<int>> images_of_frameset(
      selected.dataset.frameset_names.size());
  for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
    const int frameset = rig.dataset.images[i].frameset_index;
    if (frameset >= 0 && frameset < num_framesets && new_index[frameset] >= 0) {
      images_of_frameset[new_index[frameset]].push_back(i);
    }
  }
  for (size_t j = 0; j < images_of_frameset.size(); ++j) {
    for (const int i : images_of_frameset[j]) {
      RigImage image = rig.dataset.images[i];
      image.frameset_index = j;
      selected.dataset.images.push_back(std::move(image));
      selected.is_outlier.push_back(
          i < rig.is_outlier.size() ? rig.is_outlier[i] : std::vector<char>());
    }
  }
  return selected;
}

void SetKnownIntrinsics(SyntheticRig* rig) {
  for (size_t c = 0; c < rig->dataset.cameras.size(); ++c) {
    rig->dataset.cameras[c].camera = rig->truth.cameras[c];
    rig->dataset.cameras[c].intrinsics_known = true;
  }
}

}  // namespace rig_calibrator
