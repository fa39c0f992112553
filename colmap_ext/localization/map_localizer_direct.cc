// MapLocalizer's direct mode: the features searched in the point descriptor
// index, strongest first, until the image's 1D radial pose is certain; the
// rest matched along their radial lines (MapLocalizerOptions::guidance).
#include <colmap/util/random.h>

#include <algorithm>
#include <map>
#include <numeric>

#include "colmap_ext/localization/map_localizer.h"
#include "src/estimators/radial_pose_estimator.h"

namespace rig_calibrator {
namespace {

// Guided matching compares a feature with the points of the map images that
// see at least this fraction of the most inliers any map image sees: the
// images that overlap the image to localize. On the rendered demo, 0.2
// instead of every map image that sees an inlier costs 40 % less CPU time
// for 0.3 % fewer correspondences.
constexpr double kMinCovisibleFraction = 0.2;

// The features by decreasing scale; ties by index, so the order is fixed.
std::vector<int> StrongestFirst(const colmap::FeatureKeypoints& keypoints) {
  std::vector<int> order(keypoints.size());
  std::iota(order.begin(), order.end(), 0);
  std::vector<float> scales(keypoints.size());
  for (size_t i = 0; i < keypoints.size(); ++i) {
    scales[i] = keypoints[i].ComputeScale();
  }
  std::stable_sort(order.begin(), order.end(),
                   [&scales](int a, int b) { return scales[a] > scales[b]; });
  return order;
}

colmap::FeatureDescriptors SelectRows(
    const colmap::FeatureDescriptors& descriptors,
    const std::vector<int>& rows) {
  colmap::FeatureDescriptors selected(rows.size(), descriptors.cols());
  for (size_t i = 0; i < rows.size(); ++i) {
    selected.row(i) = descriptors.row(rows[i]);
  }
  return selected;
}

}  // namespace

bool MapLocalizer::MatchDirectly(
    const DatabaseImage& image, const colmap::FeatureKeypoints& keypoints,
    const colmap::FeatureDescriptors& descriptors,
    std::vector<CorrespondenceCandidate>* candidates, ImageLocalization* result,
    std::string* error) const {
  const double max_ratio = options_.sift_matching.max_ratio;
  const double max_distance = options_.sift_matching.max_distance;
  std::vector<PointDescriptorIndex::PointMatch> matches;
  // Searches `rows` in the index, appending to `matches` with image rows.
  const auto search_index = [&](const std::vector<int>& rows) {
    std::vector<PointDescriptorIndex::PointMatch> batch_matches;
    point_index_.Match(SelectRows(descriptors, rows), max_ratio, max_distance,
                       &batch_matches);
    for (PointDescriptorIndex::PointMatch match : batch_matches) {
      match.query_idx = static_cast<colmap::point2D_t>(rows[match.query_idx]);
      matches.push_back(match);
    }
    result->num_index_queries += static_cast<int>(rows.size());
  };

  const MapLocalizerOptions::Guidance& guidance = options_.guidance;
  if (!guidance.enabled) {
    std::vector<int> all_rows(descriptors.rows());
    std::iota(all_rows.begin(), all_rows.end(), 0);
    search_index(all_rows);
  } else {
    DatabaseCamera camera;
    if (!database_->ReadCamera(image.camera_id, &camera, error)) return false;
    const Eigen::Vector2d center(0.5 * camera.width, 0.5 * camera.height);
    std::vector<Eigen::Vector2d> points2D_centered(keypoints.size());
    for (size_t i = 0; i < keypoints.size(); ++i) {
      points2D_centered[i] =
          Eigen::Vector2d(keypoints[i].x, keypoints[i].y) - center;
    }

    const std::vector<int> order = StrongestFirst(keypoints);
    RadialPoseEstimate pose;
    bool certain = false;
    size_t num_searched = 0;
    while (num_searched < order.size() && !certain) {
      const size_t end =
          std::min(order.size(),
                   num_searched + static_cast<size_t>(guidance.batch_size));
      search_index(
          std::vector<int>(order.begin() + num_searched, order.begin() + end));
      num_searched = end;
      if (num_searched == order.size() ||
          matches.size() < static_cast<size_t>(guidance.min_pose_inliers)) {
        continue;
      }
      std::vector<Eigen::Vector2d> points2D;
      std::vector<Eigen::Vector3d> points3D;
      for (const PointDescriptorIndex::PointMatch& match : matches) {
        points2D.push_back(points2D_centered[match.query_idx]);
        points3D.push_back(map_.points.at(match.point3D_id).xyz);
      }
      // Seeded per image: the same pose on any number of threads.
      colmap::SetPRNGSeed(options_.index.seed + 7919u * image.image_id + 1u);
      certain = EstimateRadialPose(RadialPoseEstimationOptions(), points2D,
                                   points3D, &pose) &&
                pose.num_inliers >= guidance.min_pose_inliers;
    }

    if (certain && num_searched < order.size()) {
      // The map images that see many inliers (at least
      // kMinCovisibleFraction of the most any map image sees), and all of
      // their points.
      std::map<colmap::image_t, int> num_inliers_seen;
      for (size_t i = 0; i < matches.size(); ++i) {
        if (!pose.inlier_mask[i]) continue;
        for (const colmap::image_t image_id :
             map_.points.at(matches[i].point3D_id).image_ids) {
          ++num_inliers_seen[image_id];
        }
      }
      int most_seen = 0;
      for (const auto& [image_id, count] : num_inliers_seen) {
        most_seen = std::max(most_seen, count);
      }
      std::vector<colmap::image_t> map_image_ids;
      for (const auto& [image_id, count] : num_inliers_seen) {
        if (count >= kMinCovisibleFraction * most_seen) {
          map_image_ids.push_back(image_id);
        }
      }
      std::vector<colmap::point3D_t> point3D_ids;
      for (const colmap::image_t map_image_id : map_image_ids) {
        for (const colmap::point3D_t point3D_id :
             map_.image_point3D_ids.at(map_image_id)) {
          if (point3D_id != colmap::kInvalidPoint3DId) {
            point3D_ids.push_back(point3D_id);
          }
        }
      }
      std::sort(point3D_ids.begin(), point3D_ids.end());
      point3D_ids.erase(std::unique(point3D_ids.begin(), point3D_ids.end()),
                        point3D_ids.end());

      std::vector<int> near_center_rows;
      std::vector<int> guided_rows;
      for (size_t i = num_searched; i < order.size(); ++i) {
        const bool near_center = points2D_centered[order[i]].norm() <=
                                 2 * guidance.max_line_distance_px;
        (near_center ? near_center_rows : guided_rows).push_back(order[i]);
      }
      if (!near_center_rows.empty()) search_index(near_center_rows);
      RadialGuidedMatchingOptions guided_options;
      guided_options.max_line_distance_px = guidance.max_line_distance_px;
      guided_options.max_ratio = guidance.max_ratio;
      guided_options.max_distance = max_distance;
      const RadialLineIndex line_index(map_, point_index_, point3D_ids,
                                       pose.cam_from_world);
      line_index.Match(descriptors, points2D_centered, guided_rows,
                       guided_options, &matches);
      result->num_guided_queries = static_cast<int>(guided_rows.size());
    }
  }
  for (const PointDescriptorIndex::PointMatch& match : matches) {
    candidates->push_back({match.query_idx, match.point3D_id, 1, match.angle});
  }
  return true;
}

}  // namespace rig_calibrator
