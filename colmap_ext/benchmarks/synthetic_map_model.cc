#include "colmap_ext/benchmarks/synthetic_map_model.h"

#include <boost/filesystem.hpp>
#include <unordered_map>

namespace rig_calibrator {

SyntheticMapModel MakeSyntheticMapModel(const SyntheticRig& rig) {
  const RigDataset& dataset = rig.dataset;
  SyntheticMapModel result;
  for (size_t c = 0; c < dataset.map_cameras.size(); ++c) {
    colmap::Camera camera = dataset.map_cameras[c];
    camera.SetCameraId(static_cast<colmap::camera_t>(c + 1));
    result.map.AddCamera(camera);
  }
  // Per dataset point id: its track, in the order of first observation.
  std::unordered_map<int64_t, colmap::Track> tracks;
  std::vector<int64_t> point_order;
  for (size_t m = 0; m < dataset.map_images.size(); ++m) {
    const MapImage& map_image = dataset.map_images[m];
    colmap::Image image;
    image.SetImageId(static_cast<colmap::image_t>(m + 1));
    image.SetName(map_image.name);
    image.SetCameraId(
        static_cast<colmap::camera_t>(map_image.camera_index + 1));
    image.SetQvec(map_image.cam_from_world.Qvec());
    image.SetTvec(map_image.cam_from_world.translation);
    std::vector<Eigen::Vector2d> points2D;
    for (const MapObservation& observation : map_image.observations) {
      auto [it, inserted] =
          tracks.emplace(observation.point3D_id, colmap::Track());
      if (inserted) point_order.push_back(observation.point3D_id);
      it->second.AddElement(image.ImageId(),
                            static_cast<colmap::point2D_t>(points2D.size()));
      points2D.push_back(observation.point2D);
    }
    image.SetPoints2D(points2D);
    result.map.AddImage(std::move(image));
    result.map.RegisterImage(static_cast<colmap::image_t>(m + 1));
  }
  std::unordered_map<int64_t, int64_t> model_id_of;
  for (const int64_t point_id : point_order) {
    model_id_of[point_id] = static_cast<int64_t>(result.map.AddPoint3D(
        dataset.map_points3D.at(point_id), tracks.at(point_id)));
  }
  result.correspondences = DatasetCorrespondences(dataset);
  for (ImageCorrespondences& image : result.correspondences) {
    for (Correspondence& correspondence : image.correspondences) {
      const auto it = model_id_of.find(correspondence.point3D_id);
      correspondence.point3D_id = it == model_id_of.end() ? -1 : it->second;
    }
  }
  return result;
}

bool WriteSyntheticMapModel(const SyntheticMapModel& model,
                            const std::string& folder, const bool binary,
                            std::string* error) {
  const std::string sparse = folder + "/sparse";
  boost::system::error_code fs_error;
  boost::filesystem::create_directories(sparse, fs_error);
  if (fs_error) {
    *error = "cannot create " + sparse + ": " + fs_error.message();
    return false;
  }
  if (binary) {
    model.map.WriteBinary(sparse);
  } else {
    model.map.WriteText(sparse);
  }
  return WriteCorrespondenceFile(folder + "/correspondences.txt",
                                 model.correspondences, error);
}

}  // namespace rig_calibrator
