#include "colmap_ext/io/map_consistency.h"

#include <colmap/base/camera_models.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace rig_calibrator {
namespace {

std::string Id(const uint64_t id) { return std::to_string(id); }

// The point ids in increasing order, so that the repairs' examples are the
// same on every run and platform.
std::vector<colmap::point3D_t> SortedPointIds(
    const colmap::Reconstruction& map) {
  std::vector<colmap::point3D_t> ids;
  ids.reserve(map.NumPoints3D());
  for (const auto& [point3D_id, point3D] : map.Points3D()) {
    ids.push_back(point3D_id);
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

// Why `camera` cannot be projected with, or empty.
std::string CameraProblem(const colmap::Camera& camera) {
  if (camera.Width() == 0 || camera.Height() == 0) {
    return "has the image size " + Id(camera.Width()) + "x" +
           Id(camera.Height()) + "; both must be positive";
  }
  if (!camera.VerifyParams()) {
    return "has " + Id(camera.NumParams()) + " parameters, but its model " +
           camera.ModelName() + " has " +
           Id(colmap::CameraModelNumParams(camera.ModelId()));
  }
  if (!std::all_of(camera.Params().begin(), camera.Params().end(),
                   [](const double p) { return std::isfinite(p); })) {
    return "has a parameter that is not a finite number";
  }
  for (const size_t idx : camera.FocalLengthIdxs()) {
    if (!(camera.Params()[idx] > 0)) {
      return "has the focal length " + std::to_string(camera.Params()[idx]) +
             "; focal lengths must be positive";
    }
  }
  return "";
}

// The refused violations (see the header): cameras, and the images' camera
// and pose.
bool CheckCamerasAndImages(const std::string& path, const std::string& suffix,
                           const colmap::Reconstruction& map,
                           std::string* error) {
  for (const auto& [camera_id, camera] : map.Cameras()) {
    const std::string problem = CameraProblem(camera);
    if (!problem.empty()) {
      *error = path + "/cameras" + suffix + ": camera " + Id(camera_id) + " " +
               problem + " (fix or remove the camera in the map)";
      return false;
    }
  }
  for (const auto& [image_id, image] : map.Images()) {
    if (!map.ExistsCamera(image.CameraId())) {
      *error = path + "/images" + suffix + ": image " + image.Name() +
               " (id " + Id(image_id) + ") refers to camera " +
               Id(image.CameraId()) + ", which is not in " + path +
               "/cameras" + suffix;
      return false;
    }
    if (!image.Qvec().allFinite() || !image.Tvec().allFinite()) {
      *error = path + "/images" + suffix + ": image " + image.Name() +
               " (id " + Id(image_id) +
               ") has a pose that is not finite (its quaternion is zero or "
               "a value is nan or inf)";
      return false;
    }
  }
  return true;
}

// Whether `point2D` is a finite observation of point `point3D_id`.
// HasPoint3D: a point read with the id -1 (kInvalidPoint3DId, a points2D's
// "no point") is not confirmed by a points2D without a point.
bool ConfirmsPoint(const colmap::Point2D& point2D,
                   const colmap::point3D_t point3D_id) {
  return point2D.HasPoint3D() && point2D.Point3DId() == point3D_id &&
         point2D.XY().allFinite();
}

// Per image, per point2D: whether a track lists it (RepairTracks). A
// point2D names one point, and only that point's track can list it, so
// these flags say what a map from (image, point2D) to the listing point
// would (10^6 hashed entries for an output model, a third of reading it).
using TrackedPoints2D = std::unordered_map<colmap::image_t, std::vector<char>>;

// Drops the track elements that their image does not confirm (and repeated
// ones); returns the observations that the remaining tracks hold.
TrackedPoints2D RepairTracks(colmap::Reconstruction* map, MapRepairs* repairs) {
  TrackedPoints2D tracked;
  tracked.reserve(map->NumImages());
  for (const auto& [image_id, image] : map->Images()) {
    tracked[image_id].assign(image.NumPoints2D(), 0);
  }
  for (const colmap::point3D_t point3D_id : SortedPointIds(*map)) {
    colmap::Track& track = map->Point3D(point3D_id).Track();
    std::vector<colmap::TrackElement> kept;
    kept.reserve(track.Length());
    for (const colmap::TrackElement& element : track.Elements()) {
      const auto image = tracked.find(element.image_id);
      const bool confirmed =
          image != tracked.end() &&
          element.point2D_idx < image->second.size() &&
          ConfirmsPoint(
              map->Image(element.image_id).Point2D(element.point2D_idx),
              point3D_id) &&
          !image->second[element.point2D_idx];
      if (confirmed) {
        image->second[element.point2D_idx] = 1;
        kept.push_back(element);
        continue;
      }
      if (repairs->num_dropped_track_elements++ == 0) {
        repairs->dropped_track_element_example =
            "point " + Id(point3D_id) + " lists image id " +
            Id(element.image_id) + ", point2D " + Id(element.point2D_idx);
      }
    }
    if (kept.size() != track.Length()) track.SetElements(std::move(kept));
  }
  return tracked;
}

// Drops the observations that no track confirms.
void RepairObservations(const TrackedPoints2D& tracked,
                        colmap::Reconstruction* map, MapRepairs* repairs) {
  std::vector<colmap::image_t> image_ids;
  for (const auto& [image_id, image] : map->Images()) {
    image_ids.push_back(image_id);
  }
  std::sort(image_ids.begin(), image_ids.end());
  for (const colmap::image_t image_id : image_ids) {
    colmap::Image& image = map->Image(image_id);
    const std::vector<char>& listed = tracked.at(image_id);
    for (colmap::point2D_t idx = 0; idx < image.NumPoints2D(); ++idx) {
      const colmap::Point2D& point2D = image.Point2D(idx);
      if (!point2D.HasPoint3D() || listed[idx]) continue;
      if (repairs->num_dropped_observations++ == 0) {
        repairs->dropped_observation_example =
            "image " + image.Name() + ", point2D " + Id(idx) + " -> point " +
            Id(point2D.Point3DId()) +
            (map->ExistsPoint3D(point2D.Point3DId())
                 ? ", whose track does not list it"
                 : ", which is not in the map");
      }
      image.ResetPoint3DForPoint2D(idx);
    }
  }
}

// Drops the points without a track or at no finite position (the tracks
// are consistent by now, so COLMAP's DeletePoint3D finds every image).
void RepairPoints(colmap::Reconstruction* map, MapRepairs* repairs) {
  for (const colmap::point3D_t point3D_id : SortedPointIds(*map)) {
    const colmap::Point3D& point3D = map->Point3D(point3D_id);
    const bool has_track = point3D.Track().Length() > 0;
    if (has_track && point3D.XYZ().allFinite()) continue;
    if (repairs->num_dropped_points++ == 0) {
      repairs->dropped_point_example =
          "point " + Id(point3D_id) +
          (has_track ? " is not at a finite position"
                     : " has no observation an image confirms");
    }
    map->DeletePoint3D(point3D_id);
  }
}

}  // namespace

std::string MapRepairs::Describe(const std::string& path) const {
  std::string text = "the map in " + path +
                     " is inconsistent and was repaired in memory (its "
                     "files are unchanged):";
  const auto add = [&](const int64_t count, const std::string& what,
                       const std::string& example) {
    if (count == 0) return;
    text += " dropped " + std::to_string(count) + " " + what + " (e.g. " +
            example + ");";
  };
  add(num_dropped_track_elements,
      "track element(s) whose image does not observe the point",
      dropped_track_element_example);
  add(num_dropped_observations,
      "observation(s) whose point does not exist or does not list them",
      dropped_observation_example);
  add(num_dropped_points, "point(s) left without observations or position",
      dropped_point_example);
  text.pop_back();
  return text;
}

bool CheckMapConsistency(const std::string& path, const bool binary,
                         colmap::Reconstruction* map, MapRepairs* repairs,
                         std::string* error) {
  *repairs = MapRepairs();
  if (!CheckCamerasAndImages(path, binary ? ".bin" : ".txt", *map, error)) {
    return false;
  }
  const TrackedPoints2D tracked = RepairTracks(map, repairs);
  RepairObservations(tracked, map, repairs);
  RepairPoints(map, repairs);
  return true;
}

}  // namespace rig_calibrator
