// Localization of rig images against a COLMAP map (pipeline step 1): for
// every rig image, 2D-3D correspondences between its keypoints and the map's
// 3D points, deduplicated (one map point per keypoint, one keypoint per map
// point). Poses are estimated later, by the radial RANSAC.
//
// Sources of correspondences, per image:
//  * database matches: the inlier matches COLMAP's matchers stored in
//    `two_view_geometries` between the rig image and registered map images
//    (used when they exist and `use_database_matches` is on);
//  * `direct` mode (default): each feature is looked up in a FLANN index of
//    the map points' track descriptors (PointDescriptorIndex), built once per
//    map, with COLMAP's ratio test against the second-best map point;
//  * `retrieval` mode: SIFT matching (COLMAP's CPU rule on seeded forests,
//    sift_pair_matching.h) against
//    the top map images, chosen by the vocabulary tree when one is given,
//    else all map images for a small map, else the map images that see most
//    of the image's direct matches.
// Everything is read from the database; nothing is ever written to it.
//
// Why direct is the default (measured with the disabled benchmark in
// tests/colmap_ext/localization/map_localizer_test.cc, map of 300 images x 2000
// features, rig images of 2000 features): direct costs 0.26 CPU s per image
// (index of 360k descriptors built in ~3 s), i.e. ~7.5 images/s on 2 cores;
// retrieval with 10 map images costs 1.85 CPU s per image. These are with 128
// FLANN checks; the default 64 (`index.num_checks`) halves the direct cost.
#pragma once

#include <colmap/base/reconstruction.h>
#include <colmap/feature/sift.h>
#include <colmap/feature/types.h>

#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "colmap_ext/io/database_reader.h"
#include "colmap_ext/localization/correspondence_selection.h"
#include "colmap_ext/localization/localization_map.h"
#include "colmap_ext/localization/point_descriptor_index.h"
#include "colmap_ext/localization/radial_guided_matching.h"
#include "src/rig/rig_dataset.h"

namespace rig_calibrator {

enum class LocalizationMode { kDirect, kRetrieval };

// "direct" / "retrieval"; false for anything else.
bool LocalizationModeFromName(const std::string& name, LocalizationMode* mode);
std::string LocalizationModeName(LocalizationMode mode);

struct MapLocalizerOptions {
  MapLocalizerOptions();

  LocalizationMode mode = LocalizationMode::kDirect;

  // COLMAP's SiftMatching.* options. `max_ratio` (0.8) and `max_distance`
  // (0.7 rad) apply to both modes; retrieval mode also uses `cross_check`
  // (MatchSiftDescriptors; `use_gpu` is always false).
  colmap::SiftMatchingOptions sift_matching;

  // Direct mode: descriptors kept per map point (chosen by
  // SelectRepresentativeDescriptors) and the FLANN search parameters.
  int max_descriptors_per_point = 4;
  PointDescriptorIndex::Options index;

  // Direct mode, strongest features first: the features are searched in the
  // index in batches of `batch_size`, by decreasing scale (COLMAP keeps the
  // largest scales when it limits the features, as they are the most
  // repeatable), and after every batch the 1D radial pose of the matches so
  // far is estimated (EstimateRadialPose, principal point at the image
  // center). Once it has `min_pose_inliers` inliers the pose is certain: the
  // remaining features are matched only to the points their radial lines
  // pass near (RadialLineIndex, among the points of the map images that see
  // the inliers), except those within 2 max_line_distance_px of the center,
  // which go to the index. An image whose pose never becomes certain has all
  // its features searched in the index, as without guidance.
  // max_line_distance_px is the pipeline's radial inlier threshold
  // (RigCalibrator.radial_max_error_px): farther matches would be outliers of
  // its radial stage. A guided match passes Lowe's ratio test against the
  // second-nearest point near the same radial line only, a weaker test than
  // the index's against every map point, so its ratio is stricter: 0.6
  // instead of SiftMatching.max_ratio (0.8). Measured on the rendered demo
  // (scripts/benchmark_localization.sh, README, "Localization speed and map
  // scale"): with ratio 0.8 the calibration's worst camera rotation error
  // rose from 0.0053 to 0.0082 deg (unguided); with 0.6 all worst-camera
  // errors are at or below the unguided ones, for 4.5 % fewer
  // correspondences and 4.2x fewer CPU seconds per image (0.5 lost accuracy
  // again, too few correspondences).
  struct Guidance {
    bool enabled = true;  // false: every feature is searched in the index
    int batch_size = 512;
    int min_pose_inliers = 50;
    double max_line_distance_px = 8;
    // Lowe's ratio for guided matches (against the second-nearest point near
    // the same radial line).
    double max_ratio = 0.6;
  };
  Guidance guidance;

  // Retrieval mode: a COLMAP 3.8 (FLANN) vocabulary tree; without it, all map
  // images when there are at most `max_num_map_images_exhaustive`, else the
  // `num_retrieved_images` map images that see most direct matches.
  std::string vocab_tree_path;
  int num_retrieved_images = 10;
  int max_num_map_images_exhaustive = 50;

  // Use the inlier matches stored in the database between a rig image and
  // registered map images, when the image has any.
  bool use_database_matches = true;

  // -1: all cores.
  int num_threads = -1;
  // Log a progress line every this many images (0: never).
  int progress_interval = 50;

  bool Check(std::string* error) const;
};

enum class CorrespondenceSource {
  kNone,             // no correspondence found
  kDatabaseMatches,  // two_view_geometries inlier matches
  kDirectIndex,      // PointDescriptorIndex
  kImageMatching,    // SIFT matching against retrieved map images
};
std::string CorrespondenceSourceName(CorrespondenceSource source);

struct ImageLocalization {
  std::string image_name;
  colmap::image_t image_id = colmap::kInvalidImageId;     // in the database
  colmap::camera_t camera_id = colmap::kInvalidCameraId;  // in the database
  // Deduplicated; point3D_id is the map's point id.
  std::vector<Correspondence> correspondences;
  // The keypoint index of every correspondence.
  std::vector<colmap::point2D_t> point2D_idxs;
  CorrespondenceSource source = CorrespondenceSource::kNone;
  int num_candidates = 0;          // 2D-3D matches before deduplication
  int num_map_images_matched = 0;  // retrieval / database matches
  // Direct mode: features searched in the index and matched along radial
  // lines (MapLocalizerOptions::guidance; 0 when the pose was never certain).
  int num_index_queries = 0;
  int num_guided_queries = 0;
  double seconds = 0;
};

class MapLocalizer {
 public:
  // Reads, for every registered map image, the descriptors of its keypoints
  // that have a 3D point, and builds the indices the options need. The map
  // images must be in the database under their model names, with as many
  // keypoints as the model has points2D. `database` must outlive the
  // localizer. nullptr and *error on failure.
  static std::unique_ptr<MapLocalizer> Create(
      const MapLocalizerOptions& options, const colmap::Reconstruction& map,
      const DatabaseReader* database, std::string* error);
  ~MapLocalizer();

  // Localizes one database image by name.
  bool Localize(const std::string& image_name, ImageLocalization* result,
                std::string* error) const;

  // Localizes the images in parallel (options.num_threads), logging progress;
  // results in the order of `image_names`. Fails before any work if a name is
  // not in the database or has no features.
  bool LocalizeImages(const std::vector<std::string>& image_names,
                      std::vector<ImageLocalization>* results,
                      std::string* error) const;

  size_t NumMapImages() const { return map_.image_ids.size(); }
  size_t NumMapPoints() const { return map_.points.size(); }
  size_t NumIndexedDescriptors() const { return point_index_.NumDescriptors(); }

 private:
  class VocabTree;

  MapLocalizer(const MapLocalizerOptions& options,
               const DatabaseReader* database);
  // map_localizer_matching.cc: the sources of correspondences.
  bool BuildVocabTree(std::string* error);
  bool CheckImageFeatures(const DatabaseImage& image, std::string* error) const;
  bool LocalizeImage(const DatabaseImage& image, ImageLocalization* result,
                     std::string* error) const;
  // map_localizer_direct.cc: direct mode, with guidance.
  bool MatchDirectly(const DatabaseImage& image,
                     const colmap::FeatureKeypoints& keypoints,
                     const colmap::FeatureDescriptors& descriptors,
                     std::vector<CorrespondenceCandidate>* candidates,
                     ImageLocalization* result, std::string* error) const;
  bool CollectDatabaseMatches(const DatabaseImage& image,
                              const colmap::FeatureDescriptors& descriptors,
                              std::vector<CorrespondenceCandidate>* candidates,
                              int* num_map_images_matched,
                              std::string* error) const;
  std::vector<colmap::image_t> SelectMapImages(
      const colmap::FeatureKeypoints& keypoints,
      const colmap::FeatureDescriptors& descriptors) const;
  bool MatchMapImages(const std::vector<colmap::image_t>& map_image_ids,
                      const colmap::FeatureDescriptors& descriptors,
                      std::vector<CorrespondenceCandidate>* candidates,
                      int* num_map_images_matched, std::string* error) const;
  int NumThreads() const;

  MapLocalizerOptions options_;
  const DatabaseReader* database_;
  LocalizationMap map_;
  PointDescriptorIndex point_index_;
  std::unique_ptr<VocabTree> vocab_tree_;
  // Whether two_view_geometries holds any verified pair at all.
  bool has_database_matches_ = false;
};

}  // namespace rig_calibrator
