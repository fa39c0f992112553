#include "colmap_ext/io/database_export.h"

#include <colmap/base/database.h>
#include <colmap/base/essential_matrix.h>
#include <colmap/estimators/two_view_geometry.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <unordered_map>
#include <unordered_set>

#include "colmap_ext/io/database_reader.h"

namespace rig_calibrator {
namespace {

namespace fs = std::filesystem;

constexpr double kKeypointTolerancePx = 1e-3;

// The index of the keypoint at `xy` (within kKeypointTolerancePx), -1 if
// none; `order` sorts the keypoints by x.
int FindKeypoint(const colmap::FeatureKeypoints& keypoints,
                 const std::vector<int>& order, const Eigen::Vector2d& xy) {
  auto it = std::lower_bound(
      order.begin(), order.end(), xy.x() - kKeypointTolerancePx,
      [&](int k, double x) { return keypoints[k].x < x; });
  for (; it != order.end() && keypoints[*it].x <= xy.x() + kKeypointTolerancePx;
       ++it) {
    if (std::abs(keypoints[*it].y - xy.y()) <= kKeypointTolerancePx) {
      return *it;
    }
  }
  return -1;
}

// The matches of one rig image to each map image (by database image id),
// each keypoint used once per pair.
struct PairMatches {
  colmap::FeatureMatches matches;
  std::unordered_set<colmap::point2D_t> rig_used, map_used;
};

bool CheckPaths(const std::string& database_path,
                const std::string& export_path, std::string* error) {
  std::error_code code;
  if (export_path.empty() || fs::exists(export_path, code)) {
    *error = "--RigCalibrator.export_database " + export_path +
             " exists; give the path of a new file";
    return false;
  }
  if (fs::weakly_canonical(fs::absolute(export_path), code) ==
      fs::weakly_canonical(fs::absolute(database_path), code)) {
    *error = "--RigCalibrator.export_database must not be the input database " +
             database_path;
    return false;
  }
  return true;
}

// cam2_from_cam1 of two images as a calibrated two-view geometry.
colmap::TwoViewGeometry CalibratedGeometry(const Rigid3d& cam1_from_world,
                                           const Rigid3d& cam2_from_world,
                                           colmap::FeatureMatches matches) {
  const Rigid3d cam2_from_cam1 = cam2_from_world * cam1_from_world.Inverse();
  colmap::TwoViewGeometry geometry;
  geometry.config = colmap::TwoViewGeometry::CALIBRATED;
  geometry.qvec = cam2_from_cam1.Qvec();
  geometry.tvec = cam2_from_cam1.translation.normalized();
  geometry.E = colmap::EssentialMatrixFromPose(cam2_from_cam1.RotationMatrix(),
                                               geometry.tvec);
  geometry.inlier_matches = std::move(matches);
  return geometry;
}

}  // namespace

bool ExportDatabaseWithRigMatches(const std::string& database_path,
                                  const std::string& export_path,
                                  const colmap::Reconstruction& map,
                                  const RigDataset& dataset,
                                  const RigCalibration& calibration,
                                  DatabaseExportSummary* summary,
                                  std::string* error) {
  *summary = DatabaseExportSummary();
  if (!CheckPaths(database_path, export_path, error)) return false;
  DatabaseReader reader;
  if (!reader.Open(database_path, error)) return false;

  // The pairs: (rig database id, map database id) -> matches; the poses.
  std::map<std::pair<colmap::image_t, colmap::image_t>, PairMatches> pairs;
  std::unordered_map<colmap::image_t, Rigid3d> cam_from_world;
  std::map<int, std::set<colmap::camera_t>> database_cameras_of_camera;
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const RigImage& image = dataset.images[i];
    const ImageResult& result = calibration.images[i];
    if (!result.used || !calibration.rig_from_world[image.frameset_index]) {
      continue;
    }
    const DatabaseImage* rig_image = reader.FindImageWithName(image.name);
    if (rig_image == nullptr) {
      *error = "the rig image " + image.name + " is not in the database " +
               database_path;
      return false;
    }
    database_cameras_of_camera[image.camera_index].insert(rig_image->camera_id);
    cam_from_world[rig_image->image_id] =
        calibration.CamFromWorld(image.camera_index, image.frameset_index);
    colmap::FeatureKeypoints keypoints;
    if (!reader.ReadKeypoints(rig_image->image_id, &keypoints, error)) {
      return false;
    }
    std::vector<int> order(keypoints.size());
    for (size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
    std::sort(order.begin(), order.end(),
              [&](int a, int b) { return keypoints[a].x < keypoints[b].x; });
    bool has_match = false;
    for (size_t k = 0; k < image.correspondences.size(); ++k) {
      const Correspondence& correspondence = image.correspondences[k];
      if (!result.inlier_mask[k] || correspondence.point3D_id < 0 ||
          !map.ExistsPoint3D(
              static_cast<colmap::point3D_t>(correspondence.point3D_id))) {
        continue;
      }
      const int keypoint =
          FindKeypoint(keypoints, order, correspondence.point2D);
      if (keypoint < 0) {
        ++summary->num_unmatched_rows;
        continue;
      }
      const colmap::Point3D& point3D = map.Point3D(
          static_cast<colmap::point3D_t>(correspondence.point3D_id));
      for (const colmap::TrackElement& element : point3D.Track().Elements()) {
        const DatabaseImage* map_image =
            reader.FindImageWithName(map.Image(element.image_id).Name());
        if (map_image == nullptr) continue;
        PairMatches& pair = pairs[{rig_image->image_id, map_image->image_id}];
        if (pair.rig_used.count(keypoint) == 0 &&
            pair.map_used.count(element.point2D_idx) == 0) {
          pair.rig_used.insert(keypoint);
          pair.map_used.insert(element.point2D_idx);
          pair.matches.emplace_back(static_cast<colmap::point2D_t>(keypoint),
                                    element.point2D_idx);
          has_match = true;
        }
      }
    }
    summary->num_rig_images += has_match ? 1 : 0;
  }
  for (const auto& [image_id, image] : map.Images()) {
    if (const DatabaseImage* map_image =
            reader.FindImageWithName(image.Name())) {
      cam_from_world[map_image->image_id] =
          Rigid3d(Eigen::Quaterniond(image.Qvec()(0), image.Qvec()(1),
                                     image.Qvec()(2), image.Qvec()(3)),
                  image.Tvec());
    }
  }
  // A database camera shared with another rig camera keeps its parameters.
  std::map<colmap::camera_t, int> uses;
  for (const auto& [camera, ids] : database_cameras_of_camera) {
    for (const colmap::camera_t id : ids) ++uses[id];
  }
  reader.Close();

  const fs::path temporary = fs::path(export_path).parent_path() /
                             ("." + fs::path(export_path).filename().string() +
                              ".tmp-" + std::to_string(getpid()));
  std::error_code code;
  fs::copy_file(database_path, temporary, fs::copy_options::overwrite_existing,
                code);
  if (code) {
    *error = "cannot copy " + database_path + " to " + temporary.string() +
             ": " + code.message();
    return false;
  }
  {
    colmap::Database database(temporary.string());
    colmap::DatabaseTransaction transaction(&database);
    for (const auto& [camera, ids] : database_cameras_of_camera) {
      if (ids.size() != 1 || uses[*ids.begin()] != 1 ||
          !calibration.camera_calibrated[camera]) {
        continue;
      }
      colmap::Camera calibrated = calibration.cameras[camera];
      calibrated.SetCameraId(*ids.begin());
      calibrated.SetPriorFocalLength(true);
      database.UpdateCamera(calibrated);
      ++summary->num_cameras_updated;
    }
    for (const auto& [ids, pair] : pairs) {
      const auto [rig_id, map_id] = ids;
      if (database.ExistsMatches(rig_id, map_id)) {
        database.DeleteMatches(rig_id, map_id);
      }
      if (database.ExistsInlierMatches(rig_id, map_id)) {
        database.DeleteInlierMatches(rig_id, map_id);
      }
      database.WriteMatches(rig_id, map_id, pair.matches);
      database.WriteTwoViewGeometry(
          rig_id, map_id,
          CalibratedGeometry(cam_from_world.at(rig_id),
                             cam_from_world.at(map_id), pair.matches));
      ++summary->num_image_pairs;
      summary->num_matches += static_cast<int64_t>(pair.matches.size());
    }
  }
  // COLMAP opens databases in WAL mode; a closed database has merged it.
  for (const char* suffix : {"-wal", "-shm"}) {
    fs::remove(temporary.string() + suffix, code);
  }
  fs::rename(temporary, export_path, code);
  if (code) {
    fs::remove(temporary, code);
    *error = "cannot write " + export_path + ": " + code.message();
    return false;
  }
  return true;
}

}  // namespace rig_calibrator
