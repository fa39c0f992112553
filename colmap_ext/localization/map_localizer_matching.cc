// MapLocalizer's sources of 2D-3D match candidates: the database's inlier
// matches, the map images retrieved for an image (vocabulary tree or direct
// votes) and SIFT matching against them.
#include <colmap/retrieval/visual_index.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "colmap_ext/localization/map_localizer.h"
#include "colmap_ext/localization/sift_pair_matching.h"

namespace rig_calibrator {
namespace {

// A COLMAP 3.8 vocabulary tree file starts with the visual words as
// (uint64 rows, uint64 cols, rows x cols uint8). Checked before
// VisualIndex::Read, which aborts on a file it cannot parse.
bool CheckVocabTreeFile(const std::string& path, std::string* error) {
  namespace fs = std::filesystem;
  std::error_code fs_error;
  if (!fs::is_regular_file(path, fs_error)) {
    *error = "vocabulary tree " + path + ": no such file";
    return false;
  }
  std::ifstream file(path, std::ios::binary);
  uint64_t rows = 0;
  uint64_t cols = 0;
  file.read(reinterpret_cast<char*>(&rows), sizeof(rows));
  file.read(reinterpret_cast<char*>(&cols), sizeof(cols));
  const uint64_t size = fs::file_size(path, fs_error);
  if (!file || cols != 128 || rows == 0 ||
      size < 2 * sizeof(uint64_t) + rows * cols) {
    *error = "vocabulary tree " + path +
             ": not a COLMAP 3.8 vocabulary tree for SIFT (FLANN format, e.g. "
             "vocab_tree_flickr100K_words32K.bin; the faiss trees of COLMAP "
             ">= 3.12 cannot be read by 3.8)";
    return false;
  }
  return true;
}

}  // namespace

class MapLocalizer::VocabTree {
 public:
  colmap::retrieval::VisualIndex<> index;
};

// Here, where VocabTree is complete (unique_ptr<VocabTree> needs it).
MapLocalizer::MapLocalizer(const MapLocalizerOptions& options,
                           const DatabaseReader* database)
    : options_(options), database_(database) {}

MapLocalizer::~MapLocalizer() = default;

bool MapLocalizer::BuildVocabTree(std::string* error) {
  if (!CheckVocabTreeFile(options_.vocab_tree_path, error)) return false;
  vocab_tree_ = std::make_unique<VocabTree>();
  vocab_tree_->index.Read(options_.vocab_tree_path);
  colmap::retrieval::VisualIndex<>::IndexOptions index_options;
  index_options.num_threads = NumThreads();
  colmap::FeatureKeypoints keypoints;
  colmap::FeatureDescriptors descriptors;
  for (const colmap::image_t image_id : map_.image_ids) {
    if (!database_->ReadKeypoints(image_id, &keypoints, error) ||
        !database_->ReadDescriptors(image_id, &descriptors, error)) {
      return false;
    }
    vocab_tree_->index.Add(index_options, static_cast<int>(image_id), keypoints,
                           descriptors);
  }
  vocab_tree_->index.Prepare();
  return true;
}

bool MapLocalizer::CollectDatabaseMatches(
    const DatabaseImage& image, const colmap::FeatureDescriptors& descriptors,
    std::vector<CorrespondenceCandidate>* candidates,
    int* num_map_images_matched, std::string* error) const {
  colmap::FeatureMatches matches;
  for (const colmap::image_t map_image_id : map_.image_ids) {
    if (map_image_id == image.image_id) continue;
    if (!database_->ReadInlierMatches(image.image_id, map_image_id, &matches,
                                      error)) {
      return false;
    }
    const std::vector<colmap::point3D_t>& map_point3D_ids =
        map_.image_point3D_ids.at(map_image_id);
    const size_t num_before = candidates->size();
    for (const colmap::FeatureMatch& match : matches) {
      if (match.point2D_idx1 >= descriptors.rows() ||
          match.point2D_idx2 >= map_point3D_ids.size()) {
        *error = "database " + database_->path() + ": inlier matches of " +
                 image.name + " and map image " +
                 database_->FindImageWithId(map_image_id)->name +
                 " index keypoints that do not exist";
        return false;
      }
      const colmap::point3D_t point3D_id = map_point3D_ids[match.point2D_idx2];
      if (point3D_id == colmap::kInvalidPoint3DId) continue;
      candidates->push_back(
          {match.point2D_idx1, point3D_id, 1,
           point_index_.AngleToPoint(descriptors.row(match.point2D_idx1).data(),
                                     point3D_id)});
    }
    if (candidates->size() > num_before) ++*num_map_images_matched;
  }
  return true;
}

std::vector<colmap::image_t> MapLocalizer::SelectMapImages(
    const colmap::FeatureKeypoints& keypoints,
    const colmap::FeatureDescriptors& descriptors) const {
  const size_t num_images = static_cast<size_t>(options_.num_retrieved_images);
  std::vector<colmap::image_t> selected;
  if (vocab_tree_ != nullptr) {
    colmap::retrieval::VisualIndex<>::QueryOptions query_options;
    query_options.max_num_images = options_.num_retrieved_images;
    query_options.num_threads = 1;  // callers parallelize over images
    std::vector<colmap::retrieval::ImageScore> scores;
    vocab_tree_->index.Query(query_options, keypoints, descriptors, &scores);
    for (const colmap::retrieval::ImageScore& score : scores) {
      selected.push_back(static_cast<colmap::image_t>(score.image_id));
    }
    return selected;
  }
  if (map_.image_ids.size() <=
      static_cast<size_t>(options_.max_num_map_images_exhaustive)) {
    return map_.image_ids;
  }
  // The map images that observe most of the image's direct matches.
  std::vector<PointDescriptorIndex::PointMatch> matches;
  point_index_.Match(descriptors, options_.sift_matching.max_ratio,
                     options_.sift_matching.max_distance, &matches);
  std::unordered_map<colmap::image_t, int> votes;
  for (const PointDescriptorIndex::PointMatch& match : matches) {
    for (const colmap::image_t image_id :
         map_.points.at(match.point3D_id).image_ids) {
      ++votes[image_id];
    }
  }
  std::vector<std::pair<int, colmap::image_t>> ranked;
  for (const auto& [image_id, num_votes] : votes) {
    ranked.emplace_back(-num_votes, image_id);
  }
  std::sort(ranked.begin(), ranked.end());
  for (size_t i = 0; i < std::min(num_images, ranked.size()); ++i) {
    selected.push_back(ranked[i].second);
  }
  return selected;
}

bool MapLocalizer::MatchMapImages(
    const std::vector<colmap::image_t>& map_image_ids,
    const colmap::FeatureDescriptors& descriptors,
    std::vector<CorrespondenceCandidate>* candidates,
    int* num_map_images_matched, std::string* error) const {
  colmap::FeatureDescriptors map_descriptors;
  colmap::FeatureMatches matches;
  const DescriptorKdForest forest(descriptors, kPairMatchingNumTrees,
                                  options_.index.seed);
  for (const colmap::image_t map_image_id : map_image_ids) {
    if (!database_->ReadDescriptors(map_image_id, &map_descriptors, error)) {
      return false;
    }
    const std::vector<colmap::point3D_t>& map_point3D_ids =
        map_.image_point3D_ids.at(map_image_id);
    // COLMAP's rule on seeded forests (sift_pair_matching.h).
    const DescriptorKdForest map_forest(map_descriptors, kPairMatchingNumTrees,
                                        options_.index.seed);
    MatchSiftDescriptors(options_.sift_matching, descriptors, forest,
                         map_descriptors, map_forest, &matches);
    const size_t num_before = candidates->size();
    for (const colmap::FeatureMatch& match : matches) {
      const colmap::point3D_t point3D_id = map_point3D_ids[match.point2D_idx2];
      if (point3D_id == colmap::kInvalidPoint3DId) continue;
      candidates->push_back(
          {match.point2D_idx1, point3D_id, 1,
           SiftDescriptorAngle(
               descriptors.row(match.point2D_idx1).data(),
               map_descriptors.row(match.point2D_idx2).data())});
    }
    if (candidates->size() > num_before) ++*num_map_images_matched;
  }
  return true;
}

}  // namespace rig_calibrator
