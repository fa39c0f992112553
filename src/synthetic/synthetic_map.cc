#include "src/synthetic/synthetic_map.h"

#include <colmap/base/camera_models.h>

#include <random>

#include "src/synthetic/correspondence_generator.h"

namespace rig_calibrator {
namespace {

Eigen::Vector3d GaussianVector(double sigma, std::mt19937* rng) {
  std::normal_distribution<double> normal(0, sigma);
  return Eigen::Vector3d(normal(*rng), normal(*rng), normal(*rng));
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
    for (RigImage& image : dataset.images) {
      for (Correspondence& correspondence : image.correspondences) {
        correspondence.point3D = map_points[correspondence.point3D_id];
      }
    }
  }
  if (options.num_map_images == 0 || rig->truth.rig_from_world.empty()) {
    return;
  }
  for (size_t id = 0; id < map_points.size(); ++id) {
    dataset.map_points3D[static_cast<int64_t>(id)] = map_points[id];
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
    image.cam_from_world = cam_from_world;
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
      image.observations.push_back(
          {AddPixelNoise(camera, xy, options.map_noise_px, &rng),
           static_cast<int64_t>(id),
           static_cast<uint32_t>(image.observations.size())});
    }
    dataset.map_images.push_back(std::move(image));
    rig->true_map_cam_from_world.push_back(cam_from_world);
  }
}

}  // namespace rig_calibrator
