#include "colmap_ext/localization/localization_map.h"

#include <algorithm>
#include <numeric>

namespace rig_calibrator {
namespace {

bool CheckMapHasContent(const colmap::Reconstruction& map, std::string* error) {
  if (map.NumRegImages() == 0) {
    *error = "the map has no registered images";
    return false;
  }
  if (map.NumPoints3D() == 0) {
    *error =
        "the map has no 3D points: rig images are localized against map "
        "points, so the model must be a sparse reconstruction with points3D";
    return false;
  }
  return true;
}

// The map points' observation descriptors grouped by point (a counting
// sort): point i of `point3D_ids` owns rows [first_row[i], first_row[i + 1])
// of *track_descriptors.
bool GatherTrackDescriptors(const LocalizationMap& localization_map,
                            const DatabaseReader& database,
                            const std::vector<colmap::point3D_t>& point3D_ids,
                            std::vector<int>* first_row,
                            colmap::FeatureDescriptors* track_descriptors,
                            std::string* error) {
  std::unordered_map<colmap::point3D_t, int> point_index_of;
  for (size_t i = 0; i < point3D_ids.size(); ++i) {
    point_index_of[point3D_ids[i]] = static_cast<int>(i);
  }
  std::vector<int> num_rows(point3D_ids.size(), 0);
  for (const auto& [image_id, image_point3D_ids] :
       localization_map.image_point3D_ids) {
    for (const colmap::point3D_t point3D_id : image_point3D_ids) {
      if (point3D_id == colmap::kInvalidPoint3DId) continue;
      const auto it = point_index_of.find(point3D_id);
      if (it == point_index_of.end()) {
        *error = "the map is inconsistent: map image " +
                 database.FindImageWithId(image_id)->name + " observes point " +
                 std::to_string(point3D_id) + ", which is not in its points3D";
        return false;
      }
      ++num_rows[it->second];
    }
  }
  first_row->assign(point3D_ids.size() + 1, 0);
  std::partial_sum(num_rows.begin(), num_rows.end(), first_row->begin() + 1);
  track_descriptors->resize(first_row->back(), 128);
  std::vector<int> num_filled(point3D_ids.size(), 0);
  colmap::FeatureDescriptors image_descriptors;
  for (const colmap::image_t image_id : localization_map.image_ids) {
    const std::vector<colmap::point3D_t>& image_point3D_ids =
        localization_map.image_point3D_ids.at(image_id);
    if (!database.ReadDescriptors(image_id, &image_descriptors, error)) {
      return false;
    }
    if (image_descriptors.rows() !=
        static_cast<Eigen::Index>(image_point3D_ids.size())) {
      *error = "map image " + database.FindImageWithId(image_id)->name +
               " has " + std::to_string(image_point3D_ids.size()) +
               " keypoints but " + std::to_string(image_descriptors.rows()) +
               " descriptors in the database";
      return false;
    }
    for (size_t idx = 0; idx < image_point3D_ids.size(); ++idx) {
      if (image_point3D_ids[idx] == colmap::kInvalidPoint3DId) continue;
      const int i = point_index_of.at(image_point3D_ids[idx]);
      track_descriptors->row((*first_row)[i] + num_filled[i]++) =
          image_descriptors.row(idx);
    }
  }
  return true;
}

}  // namespace

bool ReadLocalizationMap(const colmap::Reconstruction& map,
                         const DatabaseReader& database,
                         LocalizationMap* localization_map,
                         std::string* error) {
  if (!CheckMapHasContent(map, error)) return false;
  std::unordered_map<colmap::image_t, colmap::image_t> database_id_of;
  for (const colmap::image_t model_image_id : map.RegImageIds()) {
    const colmap::Image& image = map.Image(model_image_id);
    const DatabaseImage* database_image =
        database.FindImageWithName(image.Name());
    if (database_image == nullptr) {
      *error = "map image " + image.Name() + " is not in the database " +
               database.path() +
               ": use the database the map was built from (or a copy of it "
               "with the rig images added)";
      return false;
    }
    const int num_keypoints = database.NumKeypoints(database_image->image_id);
    if (num_keypoints != static_cast<int>(image.NumPoints2D())) {
      *error = "map image " + image.Name() + " has " +
               std::to_string(image.NumPoints2D()) +
               " points2D in the model but " +
               std::to_string(std::max(num_keypoints, 0)) +
               " keypoints in the database: the map was not built from this "
               "database";
      return false;
    }
    database_id_of[model_image_id] = database_image->image_id;
    std::vector<colmap::point3D_t>& point3D_ids =
        localization_map->image_point3D_ids[database_image->image_id];
    point3D_ids.resize(image.NumPoints2D(), colmap::kInvalidPoint3DId);
    for (colmap::point2D_t idx = 0; idx < image.NumPoints2D(); ++idx) {
      if (image.Point2D(idx).HasPoint3D()) {
        point3D_ids[idx] = image.Point2D(idx).Point3DId();
      }
    }
    localization_map->image_ids.push_back(database_image->image_id);
  }
  std::sort(localization_map->image_ids.begin(),
            localization_map->image_ids.end());

  for (const auto& [point3D_id, point3D] : map.Points3D()) {
    LocalizationMap::Point& map_point = localization_map->points[point3D_id];
    map_point.xyz = point3D.XYZ();
    for (const colmap::TrackElement& element : point3D.Track().Elements()) {
      const auto it = database_id_of.find(element.image_id);
      if (it != database_id_of.end()) {
        map_point.image_ids.push_back(it->second);
      }
    }
  }
  return true;
}

bool IndexTrackDescriptors(const LocalizationMap& localization_map,
                           const DatabaseReader& database,
                           const int max_descriptors_per_point,
                           const int num_threads, PointDescriptorIndex* index,
                           std::string* error) {
  std::vector<colmap::point3D_t> point3D_ids;
  point3D_ids.reserve(localization_map.points.size());
  for (const auto& [point3D_id, point] : localization_map.points) {
    point3D_ids.push_back(point3D_id);
  }
  std::sort(point3D_ids.begin(), point3D_ids.end());
  std::vector<int> first_row;
  colmap::FeatureDescriptors track_descriptors;
  if (!GatherTrackDescriptors(localization_map, database, point3D_ids,
                              &first_row, &track_descriptors, error)) {
    return false;
  }

  std::vector<std::vector<int>> selected_rows(point3D_ids.size());
#pragma omp parallel for schedule(dynamic, 256) num_threads(num_threads)
  for (int i = 0; i < static_cast<int>(point3D_ids.size()); ++i) {
    const colmap::FeatureDescriptors point_descriptors =
        track_descriptors.middleRows(first_row[i],
                                     first_row[i + 1] - first_row[i]);
    selected_rows[i] = SelectRepresentativeDescriptors(
        point_descriptors, max_descriptors_per_point);
  }
  size_t num_selected = 0;
  for (const std::vector<int>& rows : selected_rows) {
    num_selected += rows.size();
  }
  colmap::FeatureDescriptors index_descriptors(num_selected, 128);
  std::vector<colmap::point3D_t> index_point3D_ids;
  index_point3D_ids.reserve(num_selected);
  for (size_t i = 0; i < point3D_ids.size(); ++i) {
    for (const int row : selected_rows[i]) {
      index_descriptors.row(index_point3D_ids.size()) =
          track_descriptors.row(first_row[i] + row);
      index_point3D_ids.push_back(point3D_ids[i]);
    }
  }
  index->SetDescriptors(std::move(index_descriptors),
                        std::move(index_point3D_ids));
  if (index->NumDescriptors() == 0) {
    *error = "no map point has a descriptor in the database";
    return false;
  }
  return true;
}

}  // namespace rig_calibrator
