#include "src/calibration/points_without_camera.h"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "src/geometry/frameset_motion.h"
#include "src/geometry/timed_rig_reprojection_cost.h"

namespace rig_calibrator {
namespace {

struct Ray {
  Eigen::Vector3d origin;
  Eigen::Vector3d direction;  // unit, in the world
};

// The ray of `pixel` seen by `camera` at pose `cam_from_world`; false when
// the pixel has no finite ray.
bool RayOf(const colmap::Camera& camera, const Rigid3d& cam_from_world,
           const Eigen::Vector2d& pixel, Ray* ray) {
  const Eigen::Vector3d in_camera =
      camera.ImageToWorld(pixel).homogeneous().normalized();
  if (!in_camera.allFinite()) return false;
  const Eigen::Quaterniond world_from_cam = cam_from_world.rotation.conjugate();
  ray->origin = cam_from_world.Center();
  ray->direction = world_from_cam * in_camera;
  return true;
}

// rig_from_world at t_f + tau: x_rig = Exp(-u(tau)) (Q_f X - p(tau))
// (frameset_motion.h) is affine in X; its columns from the images of 0 and
// the unit vectors.
Rigid3d RigFromWorldAtOffset(const Rigid3d& rig_from_world,
                             const FramesetMotion& motion,
                             const double* translation, const double tau) {
  const PoseParams pose = ToPoseParams(rig_from_world);
  Eigen::Vector3d origin;
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  WorldToRigAtOffset(pose.data(), zero.data(), motion, translation, tau,
                     origin.data());
  Eigen::Matrix3d rotation;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d unit = Eigen::Vector3d::Unit(k);
    Eigen::Vector3d image;
    WorldToRigAtOffset(pose.data(), unit.data(), motion, translation, tau,
                       image.data());
    rotation.col(k) = image - origin;
  }
  return Rigid3d(rotation, origin);
}

// X from the rays (see the header); false when they do not determine it.
bool TriangulateFromRays(const std::vector<Ray>& rays,
                         const double min_eigenvalue_ratio,
                         Eigen::Vector3d* point) {
  if (rays.size() < 2) return false;
  Eigen::Vector3d estimate = Eigen::Vector3d::Zero();
  for (int pass = 0; pass < 2; ++pass) {
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (const Ray& ray : rays) {
      const double weight =
          pass == 0 ? 1.0 : 1.0 / (estimate - ray.origin).squaredNorm();
      const Eigen::Matrix3d projector =
          Eigen::Matrix3d::Identity() - ray.direction * ray.direction.transpose();
      a += weight * projector;
      b += weight * projector * ray.origin;
    }
    if (pass == 0) {
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(a);
      const Eigen::Vector3d eigenvalues = solver.eigenvalues();  // ascending
      if (!(eigenvalues(0) >= min_eigenvalue_ratio * eigenvalues(2))) {
        return false;
      }
    }
    estimate = a.ldlt().solve(b);
    if (!estimate.allFinite()) return false;
  }
  for (const Ray& ray : rays) {
    if (!((estimate - ray.origin).dot(ray.direction) > 0)) return false;
  }
  *point = estimate;
  return true;
}

}  // namespace

std::unordered_map<int64_t, Eigen::Vector3d> PointsWithoutCamera(
    const RigDataset& dataset, const RigCalibration& calibration,
    const CaptureTimeModel& time_model, const int camera_index,
    const PointsWithoutCameraOptions& options) {
  // The camera's points, at their map positions until placed.
  std::unordered_map<int64_t, Eigen::Vector3d> points;
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const RigImage& image = dataset.images[i];
    const ImageResult& result = calibration.images[i];
    if (image.camera_index != camera_index || !result.used) continue;
    for (size_t k = 0;
         k < image.correspondences.size() && k < result.inlier_mask.size();
         ++k) {
      const Correspondence& correspondence = image.correspondences[k];
      if (result.inlier_mask[k] && correspondence.point3D_id >= 0) {
        points.emplace(correspondence.point3D_id, correspondence.point3D);
      }
    }
  }

  const bool timed =
      time_model.time_offsets_kept || time_model.line_delays_kept;
  std::vector<FramesetMotion> motions;
  if (timed) {
    motions = AdjustedFramesetMotions(dataset, calibration);
  }

  std::unordered_map<int64_t, std::vector<Ray>> rays;
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const RigImage& image = dataset.images[i];
    const ImageResult& result = calibration.images[i];
    const int c = image.camera_index;
    if (c == camera_index || !result.used || !calibration.camera_calibrated[c] ||
        !calibration.rig_from_world[image.frameset_index]) {
      continue;
    }
    const Rigid3d& rig_from_world =
        *calibration.rig_from_world[image.frameset_index];
    double offset = 0, line_delay = 0;
    if (timed) {
      offset = time_model.time_offsets_kept
                   ? time_model.cameras[c].time_offset_s
                   : 0;
      line_delay = time_model.line_delays_kept
                       ? time_model.cameras[c].line_delay_s
                       : 0;
    }
    for (size_t k = 0;
         k < image.correspondences.size() && k < result.inlier_mask.size();
         ++k) {
      const Correspondence& correspondence = image.correspondences[k];
      if (!result.inlier_mask[k] || points.count(correspondence.point3D_id) == 0) {
        continue;
      }
      Rigid3d cam_from_world;
      if (timed) {
        const FramesetMotion& motion = motions[image.frameset_index];
        cam_from_world =
            calibration.cam_from_rig[c] *
            RigFromWorldAtOffset(
                rig_from_world, motion, &motion[9],
                CaptureTimeOfRow(offset, line_delay,
                                 correspondence.point2D.y()));
      } else {
        cam_from_world = calibration.cam_from_rig[c] * rig_from_world;
      }
      Ray ray;
      if (RayOf(calibration.cameras[c], cam_from_world, correspondence.point2D,
                &ray)) {
        rays[correspondence.point3D_id].push_back(ray);
      }
    }
  }
  const bool map_adjusted =
      options.map_observations &&
      calibration.map_observation_rejected.size() == dataset.map_images.size() &&
      calibration.map_cam_from_world.size() == dataset.map_images.size() &&
      calibration.map_cameras.size() == dataset.map_cameras.size();
  for (size_t m = 0; map_adjusted && m < dataset.map_images.size(); ++m) {
    const MapImage& image = dataset.map_images[m];
    const colmap::Camera& camera = calibration.map_cameras[image.camera_index];
    for (size_t k = 0; k < image.observations.size(); ++k) {
      const MapObservation& observation = image.observations[k];
      if (k >= calibration.map_observation_rejected[m].size() ||
          calibration.map_observation_rejected[m][k] ||
          points.count(observation.point3D_id) == 0) {
        continue;
      }
      Ray ray;
      if (RayOf(camera, calibration.map_cam_from_world[m], observation.point2D,
                &ray)) {
        rays[observation.point3D_id].push_back(ray);
      }
    }
  }

  const double half_angle = 0.5 * options.min_angle_deg * M_PI / 180;
  const double min_eigenvalue_ratio = std::pow(std::sin(half_angle), 2);
  for (const auto& [point3D_id, point_rays] : rays) {
    TriangulateFromRays(point_rays, min_eigenvalue_ratio, &points[point3D_id]);
  }
  return points;
}

}  // namespace rig_calibrator
