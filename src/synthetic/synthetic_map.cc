#include "src/synthetic/synthetic_map.h"

#include <colmap/base/camera_models.h>
#include <colmap/base/triangulation.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <random>
#include <unordered_map>

#include "src/synthetic/correspondence_generator.h"

namespace rig_calibrator {
namespace {

Eigen::Vector3d GaussianVector(double sigma, std::mt19937* rng) {
  std::normal_distribution<double> normal(0, sigma);
  return Eigen::Vector3d(normal(*rng), normal(*rng), normal(*rng));
}

// Points with a smaller largest angle between their rays are not
// triangulated (COLMAP's mapper filters them the same way: 1.5 degrees).
constexpr double kMinTriangulationAngleDeg = 1.5;

// The pose of map image m of M as the map holds it (see
// SyntheticRigOptions::map_pose_noise_deg): in the world warped by the drift
// at t = m / (M - 1), x' = pivot + s_t R_t (x - pivot), R_t about z by
// t * map_drift_deg, s_t = 1 + t * map_scale_drift, then off by the
// per-image noise (rotation on the left, centre added).
Rigid3d MapPoseAsMapped(const SyntheticRigOptions& options,
                        const Rigid3d& true_cam_from_world,
                        const Eigen::Vector3d& pivot, int m,
                        std::mt19937* rng) {
  const double t = options.num_map_images > 1
                       ? static_cast<double>(m) / (options.num_map_images - 1)
                       : 0;
  const Eigen::Matrix3d drift =
      Eigen::AngleAxisd(t * options.map_drift_deg * M_PI / 180,
                        Eigen::Vector3d::UnitZ())
          .toRotationMatrix();
  const double scale = 1 + t * options.map_scale_drift;
  std::normal_distribution<double> normal(0, 1);
  const Eigen::Vector3d rotation_noise =
      options.map_pose_noise_deg * M_PI / 180 *
      Eigen::Vector3d(normal(*rng), normal(*rng), normal(*rng));
  const Eigen::Vector3d center_noise =
      options.map_pose_noise *
      Eigen::Vector3d(normal(*rng), normal(*rng), normal(*rng));
  Eigen::Matrix3d rotation =
      true_cam_from_world.RotationMatrix() * drift.transpose();
  if (rotation_noise.norm() > 0) {
    rotation = Eigen::AngleAxisd(rotation_noise.norm(),
                                 rotation_noise.normalized())
                   .toRotationMatrix() *
               rotation;
  }
  const Eigen::Vector3d center =
      pivot + scale * drift * (true_cam_from_world.Center() - pivot) +
      center_noise;
  return Rigid3d(rotation, -rotation * center);
}

// The map points that >= 2 map images observe, triangulated (COLMAP's
// multi-view DLT) from those observations through the map images' poses as
// mapped; a point whose rays meet at less than kMinTriangulationAngleDeg,
// or that lands behind a camera, keeps its value.
void TriangulateMapPoints(const RigDataset& dataset,
                          std::vector<Eigen::Vector3d>* map_points) {
  std::vector<std::vector<std::pair<int, Eigen::Vector2d>>> tracks(
      map_points->size());
  for (size_t m = 0; m < dataset.map_images.size(); ++m) {
    const MapImage& image = dataset.map_images[m];
    const colmap::Camera& camera = dataset.map_cameras[image.camera_index];
    for (const MapObservation& observation : image.observations) {
      tracks[observation.point3D_id].emplace_back(
          static_cast<int>(m), camera.ImageToWorld(observation.point2D));
    }
  }
  for (size_t id = 0; id < tracks.size(); ++id) {
    if (tracks[id].size() < 2) continue;
    std::vector<Eigen::Matrix3x4d> projections;
    std::vector<Eigen::Vector2d> points;
    for (const auto& [m, normalized] : tracks[id]) {
      const Rigid3d& pose = dataset.map_images[m].cam_from_world;
      Eigen::Matrix3x4d projection;
      projection << pose.RotationMatrix(), pose.translation;
      projections.push_back(projection);
      points.push_back(normalized);
    }
    const Eigen::Vector3d point =
        colmap::TriangulateMultiViewPoint(projections, points);
    if (!point.allFinite()) continue;
    double max_angle = 0;
    bool in_front = true;
    for (size_t a = 0; a < tracks[id].size(); ++a) {
      const Rigid3d& pose_a = dataset.map_images[tracks[id][a].first].cam_from_world;
      in_front = in_front && (pose_a * point).z() > 0;
      for (size_t b = a + 1; b < tracks[id].size(); ++b) {
        const Rigid3d& pose_b =
            dataset.map_images[tracks[id][b].first].cam_from_world;
        const Eigen::Vector3d ray_a = point - pose_a.Center();
        const Eigen::Vector3d ray_b = point - pose_b.Center();
        max_angle = std::max(
            max_angle, std::acos(std::clamp(
                           ray_a.normalized().dot(ray_b.normalized()), -1.0,
                           1.0)));
      }
    }
    if (in_front && max_angle * 180 / M_PI >= kMinTriangulationAngleDeg) {
      (*map_points)[id] = point;
    }
  }
}

// Keeps `count` of a map image's visible points (id, pixel): the rig's
// points first, each group in a random order, then back in id order.
void KeepObservations(int count, const std::vector<char>& rig_observed,
                      std::mt19937* rng,
                      std::vector<std::pair<int64_t, Eigen::Vector2d>>* visible) {
  std::shuffle(visible->begin(), visible->end(), *rng);
  std::stable_partition(visible->begin(), visible->end(), [&](const auto& v) {
    return rig_observed[v.first] != 0;
  });
  visible->resize(count);
  std::sort(visible->begin(), visible->end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
}

}  // namespace

void AddSyntheticMap(const SyntheticRigOptions& options, SyntheticRig* rig) {
  std::mt19937 rng(options.seed + 1);
  RigDataset& dataset = rig->dataset;
  const std::vector<Eigen::Vector3d>& truth = rig->true_points3D;
  std::vector<Eigen::Vector3d> map_points = truth;
  if (options.map_point_noise > 0) {
    for (Eigen::Vector3d& point : map_points) {
      point += GaussianVector(options.map_point_noise, &rng);
    }
  }
  // The correspondences and map_points3D get the map's points (also the
  // triangulated ones, below).
  const auto give_map_points = [&]() {
    for (RigImage& image : dataset.images) {
      for (Correspondence& correspondence : image.correspondences) {
        correspondence.point3D = map_points[correspondence.point3D_id];
      }
    }
    if (options.num_map_images == 0) return;
    for (size_t id = 0; id < map_points.size(); ++id) {
      dataset.map_points3D[static_cast<int64_t>(id)] = map_points[id];
    }
  };
  if (options.num_map_images == 0 || rig->truth.rig_from_world.empty()) {
    if (options.map_point_noise > 0) give_map_points();
    return;
  }
  const colmap::Camera& size_of = rig->truth.cameras[0];
  colmap::Camera camera;
  camera.SetCameraId(1);
  camera.InitializeWithName("PINHOLE", 0.7 * size_of.Width(), size_of.Width(),
                            size_of.Height());
  dataset.map_cameras = {camera};

  const int num_cameras = static_cast<int>(rig->truth.cameras.size());
  const int num_framesets = static_cast<int>(rig->truth.rig_from_world.size());
  std::uniform_real_distribution<double> unit(-1, 1);
  // The map's pose errors from a stream of their own: without them the
  // dataset is the same as before they existed.
  std::mt19937 pose_rng(options.seed + 2);
  // The cap's draws from a stream of their own too; the points some rig image
  // observes (correctly) come first, as a map holds what was matched.
  std::mt19937 cap_rng(options.seed + 3);
  std::vector<char> rig_observed;
  if (options.map_observations_per_image > 0) {
    rig_observed.assign(truth.size(), 0);
    for (size_t i = 0; i < dataset.images.size(); ++i) {
      for (size_t k = 0; k < dataset.images[i].correspondences.size(); ++k) {
        if (rig->is_outlier[i][k]) continue;
        rig_observed[dataset.images[i].correspondences[k].point3D_id] = 1;
      }
    }
  }
  for (int m = 0; m < options.num_map_images; ++m) {
    const int c = m % num_cameras;
    const int j =
        std::min(num_framesets - 1, m * num_framesets / options.num_map_images);
    const Rigid3d rig_camera =
        rig->truth.cam_from_rig[c] * rig->truth.rig_from_world[j];
    // Rotated by up to 3 degrees about a random axis, the center moved by
    // up to 0.2 map units along each axis.
    const Eigen::Vector3d axis =
        Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
    const double angle = unit(rng) * 3.0 * M_PI / 180;
    const Eigen::Vector3d offset(0.2 * unit(rng), 0.2 * unit(rng),
                                 0.2 * unit(rng));
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(angle, axis).toRotationMatrix() *
        rig_camera.RotationMatrix();
    const Eigen::Vector3d center = rig_camera.Center() + offset;
    const Rigid3d cam_from_world(rotation, -rotation * center);

    MapImage image;
    image.name = "map/" + FramesetName(m) + ".png";
    image.image_id = m + 1;
    image.camera_index = 0;
    image.cam_from_world = MapPoseAsMapped(
        options, cam_from_world, rig->truth.rig_from_world[0].Center(), m,
        &pose_rng);
    std::vector<std::pair<int64_t, Eigen::Vector2d>> visible;
    for (size_t id = 0; id < truth.size(); ++id) {
      const Eigen::Vector3d point_in_cam = cam_from_world * truth[id];
      if (point_in_cam.z() <= 0 ||
          point_in_cam.norm() > 2 * options.max_depth) {
        continue;
      }
      const Eigen::Vector2d xy =
          camera.WorldToImage(point_in_cam.hnormalized());
      if (xy.x() < 0 || xy.y() < 0 || xy.x() > camera.Width() ||
          xy.y() > camera.Height()) {
        continue;
      }
      visible.emplace_back(static_cast<int64_t>(id), xy);
    }
    if (options.map_observations_per_image > 0 &&
        static_cast<int>(visible.size()) > options.map_observations_per_image) {
      KeepObservations(options.map_observations_per_image, rig_observed,
                       &cap_rng, &visible);
    }
    for (const auto& [id, xy] : visible) {
      image.observations.push_back(
          {AddPixelNoise(camera, xy, options.map_noise_px, &rng), id,
           static_cast<uint32_t>(image.observations.size())});
    }
    dataset.map_images.push_back(std::move(image));
    rig->true_map_cam_from_world.push_back(cam_from_world);
  }
  if (options.triangulate_map_points) {
    TriangulateMapPoints(dataset, &map_points);
  }
  give_map_points();
}

void KeepCorrespondencesWithMapTracks(SyntheticRig* rig) {
  if (rig->dataset.map_images.empty()) return;
  std::unordered_map<int64_t, int> num_observations;
  for (const MapImage& image : rig->dataset.map_images) {
    for (const MapObservation& observation : image.observations) {
      ++num_observations[observation.point3D_id];
    }
  }
  for (RigImage& image : rig->dataset.images) {
    std::vector<Correspondence> kept;
    for (const Correspondence& correspondence : image.correspondences) {
      if (num_observations[correspondence.point3D_id] >= 2) {
        kept.push_back(correspondence);
      }
    }
    image.correspondences = kept;
  }
}

}  // namespace rig_calibrator
