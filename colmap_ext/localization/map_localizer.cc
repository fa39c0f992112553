#include "colmap_ext/localization/map_localizer.h"

#include <colmap/retrieval/visual_index.h>
#include <glog/logging.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <tuple>
#include <unordered_set>

namespace rig_calibrator {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(const Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string MissingImageMessage(const DatabaseReader& database,
                                const std::string& name) {
  return "the database " + database.path() + " has no image named " + name +
         ": run colmap feature_extractor on the rig images into this "
         "database first (see README)";
}

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

bool LocalizationModeFromName(const std::string& name, LocalizationMode* mode) {
  if (name == "direct") {
    *mode = LocalizationMode::kDirect;
  } else if (name == "retrieval") {
    *mode = LocalizationMode::kRetrieval;
  } else {
    return false;
  }
  return true;
}

std::string LocalizationModeName(const LocalizationMode mode) {
  return mode == LocalizationMode::kDirect ? "direct" : "retrieval";
}

std::string CorrespondenceSourceName(const CorrespondenceSource source) {
  switch (source) {
    case CorrespondenceSource::kNone:
      return "none";
    case CorrespondenceSource::kDatabaseMatches:
      return "database_matches";
    case CorrespondenceSource::kDirectIndex:
      return "direct_index";
    case CorrespondenceSource::kImageMatching:
      return "image_matching";
  }
  return "none";
}

MapLocalizerOptions::MapLocalizerOptions() {
  // The GPU matcher needs an OpenGL context or CUDA (colmap_api.md §5); the
  // CPU matcher runs one pair per thread here.
  sift_matching.use_gpu = false;
  sift_matching.num_threads = 1;
}

bool MapLocalizerOptions::Check(std::string* error) const {
  const auto fail = [error](const std::string& message) {
    *error = "invalid localization options: " + message;
    return false;
  };
  if (sift_matching.use_gpu) return fail("SiftMatching.use_gpu must be false");
  if (!sift_matching.Check()) {
    return fail("SiftMatching options out of range (see the log)");
  }
  if (max_descriptors_per_point < 1) {
    return fail("max_descriptors_per_point must be >= 1");
  }
  if (index.num_trees < 1 || index.num_checks < 1) {
    return fail("index num_trees and num_checks must be >= 1");
  }
  if (num_retrieved_images < 1)
    return fail("num_retrieved_images must be >= 1");
  if (max_num_map_images_exhaustive < 0) {
    return fail("max_num_map_images_exhaustive must be >= 0");
  }
  if (num_threads == 0 || num_threads < -1) {
    return fail("num_threads must be -1 (all cores) or >= 1");
  }
  if (progress_interval < 0) return fail("progress_interval must be >= 0");
  return true;
}

std::vector<CorrespondenceCandidate> SelectOneToOneCorrespondences(
    std::vector<CorrespondenceCandidate> candidates) {
  std::sort(
      candidates.begin(), candidates.end(),
      [](const CorrespondenceCandidate& a, const CorrespondenceCandidate& b) {
        return std::tie(a.point2D_idx, a.point3D_id) <
               std::tie(b.point2D_idx, b.point3D_id);
      });
  std::vector<CorrespondenceCandidate> merged;
  for (const CorrespondenceCandidate& candidate : candidates) {
    if (!merged.empty() && merged.back().point2D_idx == candidate.point2D_idx &&
        merged.back().point3D_id == candidate.point3D_id) {
      merged.back().votes += candidate.votes;
      merged.back().angle = std::min(merged.back().angle, candidate.angle);
    } else {
      merged.push_back(candidate);
    }
  }
  std::sort(
      merged.begin(), merged.end(),
      [](const CorrespondenceCandidate& a, const CorrespondenceCandidate& b) {
        return std::make_tuple(-a.votes, a.angle, a.point2D_idx, a.point3D_id) <
               std::make_tuple(-b.votes, b.angle, b.point2D_idx, b.point3D_id);
      });
  std::unordered_set<colmap::point2D_t> taken_points2D;
  std::unordered_set<colmap::point3D_t> taken_points3D;
  std::vector<CorrespondenceCandidate> selected;
  for (const CorrespondenceCandidate& candidate : merged) {
    if (taken_points2D.count(candidate.point2D_idx) > 0 ||
        taken_points3D.count(candidate.point3D_id) > 0) {
      continue;
    }
    taken_points2D.insert(candidate.point2D_idx);
    taken_points3D.insert(candidate.point3D_id);
    selected.push_back(candidate);
  }
  return selected;
}

class MapLocalizer::VocabTree {
 public:
  colmap::retrieval::VisualIndex<> index;
};

MapLocalizer::MapLocalizer(const MapLocalizerOptions& options,
                           const DatabaseReader* database)
    : options_(options), database_(database) {}

MapLocalizer::~MapLocalizer() = default;

int MapLocalizer::NumThreads() const {
  return options_.num_threads > 0 ? options_.num_threads
                                  : omp_get_max_threads();
}

std::unique_ptr<MapLocalizer> MapLocalizer::Create(
    const MapLocalizerOptions& options, const colmap::Reconstruction& map,
    const DatabaseReader* database, std::string* error) {
  if (!options.Check(error)) return nullptr;
  if (database == nullptr || !database->IsOpen()) {
    *error = "the localizer needs an open database";
    return nullptr;
  }
  std::unique_ptr<MapLocalizer> localizer(new MapLocalizer(options, database));
  const Clock::time_point start = Clock::now();
  if (!localizer->ReadMap(map, error)) return nullptr;

  const bool needs_search_index =
      options.mode == LocalizationMode::kDirect ||
      (options.vocab_tree_path.empty() &&
       localizer->NumMapImages() >
           static_cast<size_t>(options.max_num_map_images_exhaustive));
  if (needs_search_index) {
    localizer->point_index_.BuildSearchIndex(options.index);
  }
  if (options.mode == LocalizationMode::kRetrieval &&
      !options.vocab_tree_path.empty() && !localizer->BuildVocabTree(error)) {
    return nullptr;
  }
  LOG(INFO) << "Map for localization (" << LocalizationModeName(options.mode)
            << "): " << localizer->NumMapImages() << " images, "
            << localizer->NumMapPoints() << " points, "
            << localizer->NumIndexedDescriptors() << " point descriptors"
            << (needs_search_index ? " in a kd-tree index" : "")
            << (localizer->vocab_tree_ != nullptr ? ", vocabulary tree" : "")
            << "; ready in " << SecondsSince(start) << " s";
  return localizer;
}

bool MapLocalizer::ReadMap(const colmap::Reconstruction& map,
                           std::string* error) {
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

  // Model and database may number images differently; names link them.
  std::unordered_map<colmap::image_t, colmap::image_t> database_id_of;
  for (const colmap::image_t model_image_id : map.RegImageIds()) {
    const colmap::Image& image = map.Image(model_image_id);
    const DatabaseImage* database_image =
        database_->FindImageWithName(image.Name());
    if (database_image == nullptr) {
      *error = "map image " + image.Name() + " is not in the database " +
               database_->path() +
               ": use the database the map was built from (or a copy of it "
               "with the rig images added)";
      return false;
    }
    const int num_keypoints = database_->NumKeypoints(database_image->image_id);
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
        map_image_point3D_ids_[database_image->image_id];
    point3D_ids.resize(image.NumPoints2D(), colmap::kInvalidPoint3DId);
    for (colmap::point2D_t idx = 0; idx < image.NumPoints2D(); ++idx) {
      if (image.Point2D(idx).HasPoint3D()) {
        point3D_ids[idx] = image.Point2D(idx).Point3DId();
      }
    }
    map_image_ids_.push_back(database_image->image_id);
  }
  std::sort(map_image_ids_.begin(), map_image_ids_.end());

  std::vector<colmap::point3D_t> point3D_ids;
  point3D_ids.reserve(map.NumPoints3D());
  for (const auto& [point3D_id, point3D] : map.Points3D()) {
    point3D_ids.push_back(point3D_id);
    MapPoint& map_point = map_points_[point3D_id];
    map_point.xyz = point3D.XYZ();
    for (const colmap::TrackElement& element : point3D.Track().Elements()) {
      const auto it = database_id_of.find(element.image_id);
      if (it != database_id_of.end()) {
        map_point.image_ids.push_back(it->second);
      }
    }
  }
  std::sort(point3D_ids.begin(), point3D_ids.end());

  // The observations' descriptors, grouped by point (a counting sort): point
  // i owns rows [first_row[i], first_row[i] + num_rows[i]).
  std::unordered_map<colmap::point3D_t, int> point_index_of;
  for (size_t i = 0; i < point3D_ids.size(); ++i) {
    point_index_of[point3D_ids[i]] = static_cast<int>(i);
  }
  std::vector<int> num_rows(point3D_ids.size(), 0);
  for (const auto& [image_id, image_point3D_ids] : map_image_point3D_ids_) {
    for (const colmap::point3D_t point3D_id : image_point3D_ids) {
      if (point3D_id == colmap::kInvalidPoint3DId) continue;
      const auto it = point_index_of.find(point3D_id);
      if (it == point_index_of.end()) {
        *error = "the map is inconsistent: map image " +
                 database_->FindImageWithId(image_id)->name +
                 " observes point " + std::to_string(point3D_id) +
                 ", which is not in its points3D";
        return false;
      }
      ++num_rows[it->second];
    }
  }
  std::vector<int> first_row(point3D_ids.size() + 1, 0);
  std::partial_sum(num_rows.begin(), num_rows.end(), first_row.begin() + 1);
  colmap::FeatureDescriptors track_descriptors(first_row.back(), 128);
  std::vector<int> num_filled(point3D_ids.size(), 0);
  colmap::FeatureDescriptors image_descriptors;
  for (const colmap::image_t image_id : map_image_ids_) {
    const std::vector<colmap::point3D_t>& image_point3D_ids =
        map_image_point3D_ids_.at(image_id);
    if (!database_->ReadDescriptors(image_id, &image_descriptors, error)) {
      return false;
    }
    if (image_descriptors.rows() !=
        static_cast<Eigen::Index>(image_point3D_ids.size())) {
      *error = "map image " + database_->FindImageWithId(image_id)->name +
               " has " + std::to_string(image_point3D_ids.size()) +
               " keypoints but " + std::to_string(image_descriptors.rows()) +
               " descriptors in the database";
      return false;
    }
    for (size_t idx = 0; idx < image_point3D_ids.size(); ++idx) {
      if (image_point3D_ids[idx] == colmap::kInvalidPoint3DId) continue;
      const int i = point_index_of.at(image_point3D_ids[idx]);
      track_descriptors.row(first_row[i] + num_filled[i]++) =
          image_descriptors.row(idx);
    }
  }

  std::vector<std::vector<int>> selected_rows(point3D_ids.size());
#pragma omp parallel for schedule(dynamic, 256) num_threads(NumThreads())
  for (int i = 0; i < static_cast<int>(point3D_ids.size()); ++i) {
    const colmap::FeatureDescriptors point_descriptors =
        track_descriptors.middleRows(first_row[i], num_rows[i]);
    selected_rows[i] = SelectRepresentativeDescriptors(
        point_descriptors, options_.max_descriptors_per_point);
  }
  size_t num_selected = 0;
  for (const std::vector<int>& rows : selected_rows)
    num_selected += rows.size();
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
  point_index_.SetDescriptors(std::move(index_descriptors),
                              std::move(index_point3D_ids));
  if (point_index_.NumDescriptors() == 0) {
    *error = "no map point has a descriptor in the database";
    return false;
  }
  has_database_matches_ = database_->NumVerifiedImagePairs() > 0;
  return true;
}

bool MapLocalizer::BuildVocabTree(std::string* error) {
  if (!CheckVocabTreeFile(options_.vocab_tree_path, error)) return false;
  vocab_tree_ = std::make_unique<VocabTree>();
  vocab_tree_->index.Read(options_.vocab_tree_path);
  colmap::retrieval::VisualIndex<>::IndexOptions index_options;
  index_options.num_threads = NumThreads();
  colmap::FeatureKeypoints keypoints;
  colmap::FeatureDescriptors descriptors;
  for (const colmap::image_t image_id : map_image_ids_) {
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

bool MapLocalizer::CheckImageFeatures(const DatabaseImage& image,
                                      std::string* error) const {
  const int num_keypoints = database_->NumKeypoints(image.image_id);
  const int num_descriptors = database_->NumDescriptors(image.image_id);
  const std::string hint =
      ": run colmap feature_extractor on the rig images into this database "
      "first (see README)";
  if (num_keypoints < 0) {
    *error = "the database " + database_->path() +
             " has no keypoints for image " + image.name + hint;
    return false;
  }
  if (num_descriptors < 0) {
    *error = "the database " + database_->path() +
             " has no descriptors for image " + image.name + hint;
    return false;
  }
  if (num_keypoints != num_descriptors) {
    *error = "image " + image.name + " has " + std::to_string(num_keypoints) +
             " keypoints but " + std::to_string(num_descriptors) +
             " descriptors in the database " + database_->path();
    return false;
  }
  return true;
}

bool MapLocalizer::Localize(const std::string& image_name,
                            ImageLocalization* result,
                            std::string* error) const {
  const DatabaseImage* image = database_->FindImageWithName(image_name);
  if (image == nullptr) {
    *error = MissingImageMessage(*database_, image_name);
    return false;
  }
  return CheckImageFeatures(*image, error) &&
         LocalizeImage(*image, result, error);
}

bool MapLocalizer::LocalizeImages(const std::vector<std::string>& image_names,
                                  std::vector<ImageLocalization>* results,
                                  std::string* error) const {
  std::vector<const DatabaseImage*> images;
  std::vector<std::string> missing;
  for (const std::string& name : image_names) {
    images.push_back(database_->FindImageWithName(name));
    if (images.back() == nullptr) missing.push_back(name);
  }
  if (!missing.empty()) {
    *error = MissingImageMessage(*database_, missing.front());
    if (missing.size() > 1) {
      *error += " (" + std::to_string(missing.size() - 1) +
                " more rig images are missing)";
    }
    return false;
  }
  for (const DatabaseImage* image : images) {
    if (!CheckImageFeatures(*image, error)) return false;
    if (map_image_point3D_ids_.count(image->image_id) > 0) {
      LOG(WARNING) << "Rig image " << image->name
                   << " is also a registered map image; it will match its "
                      "own map points";
    }
  }

  const int num_images = static_cast<int>(images.size());
  results->assign(num_images, ImageLocalization());
  std::vector<std::string> errors(num_images);
  std::atomic<int> num_done(0);
  const Clock::time_point start = Clock::now();
#pragma omp parallel for schedule(dynamic, 1) num_threads(NumThreads())
  for (int i = 0; i < num_images; ++i) {
    LocalizeImage(*images[i], &(*results)[i], &errors[i]);
    const int done = ++num_done;
    if (options_.progress_interval > 0 &&
        (done % options_.progress_interval == 0 || done == num_images)) {
      const double seconds = SecondsSince(start);
      LOG(INFO) << "localized " << done << "/" << num_images << " images, "
                << (seconds > 0 ? done / seconds : 0.0) << " images/s";
    }
  }
  for (const std::string& image_error : errors) {
    if (!image_error.empty()) {
      *error = image_error;
      return false;
    }
  }

  size_t num_correspondences = 0;
  int num_empty = 0;
  for (const ImageLocalization& result : *results) {
    num_correspondences += result.correspondences.size();
    num_empty += result.correspondences.empty() ? 1 : 0;
  }
  LOG(INFO) << "Localized " << num_images << " images in "
            << SecondsSince(start) << " s: " << num_correspondences
            << " 2D-3D correspondences, " << num_empty << " images without any";
  return true;
}

bool MapLocalizer::LocalizeImage(const DatabaseImage& image,
                                 ImageLocalization* result,
                                 std::string* error) const {
  const Clock::time_point start = Clock::now();
  *result = ImageLocalization();
  result->image_name = image.name;
  result->image_id = image.image_id;
  result->camera_id = image.camera_id;

  colmap::FeatureKeypoints keypoints;
  colmap::FeatureDescriptors descriptors;
  if (!database_->ReadKeypoints(image.image_id, &keypoints, error) ||
      !database_->ReadDescriptors(image.image_id, &descriptors, error)) {
    return false;
  }
  if (keypoints.size() != static_cast<size_t>(descriptors.rows())) {
    *error = "image " + image.name + " has " +
             std::to_string(keypoints.size()) + " keypoints but " +
             std::to_string(descriptors.rows()) + " descriptors";
    return false;
  }

  std::vector<CorrespondenceCandidate> candidates;
  if (options_.use_database_matches && has_database_matches_) {
    if (!CollectDatabaseMatches(image, descriptors, &candidates,
                                &result->num_map_images_matched, error)) {
      return false;
    }
    if (!candidates.empty()) {
      result->source = CorrespondenceSource::kDatabaseMatches;
    }
  }
  if (candidates.empty() && descriptors.rows() > 0) {
    if (options_.mode == LocalizationMode::kDirect) {
      std::vector<PointDescriptorIndex::PointMatch> matches;
      point_index_.Match(descriptors, options_.sift_matching.max_ratio,
                         options_.sift_matching.max_distance, &matches);
      for (const PointDescriptorIndex::PointMatch& match : matches) {
        candidates.push_back(
            {match.query_idx, match.point3D_id, 1, match.angle});
      }
      result->source = CorrespondenceSource::kDirectIndex;
    } else {
      if (!MatchMapImages(SelectMapImages(keypoints, descriptors), descriptors,
                          &candidates, &result->num_map_images_matched,
                          error)) {
        return false;
      }
      result->source = CorrespondenceSource::kImageMatching;
    }
  }
  if (candidates.empty()) result->source = CorrespondenceSource::kNone;
  result->num_candidates = static_cast<int>(candidates.size());

  std::vector<CorrespondenceCandidate> selected =
      SelectOneToOneCorrespondences(std::move(candidates));
  std::sort(
      selected.begin(), selected.end(),
      [](const CorrespondenceCandidate& a, const CorrespondenceCandidate& b) {
        return a.point2D_idx < b.point2D_idx;
      });
  for (const CorrespondenceCandidate& candidate : selected) {
    Correspondence correspondence;
    const colmap::FeatureKeypoint& keypoint = keypoints[candidate.point2D_idx];
    correspondence.point2D = Eigen::Vector2d(keypoint.x, keypoint.y);
    correspondence.point3D = map_points_.at(candidate.point3D_id).xyz;
    correspondence.point3D_id = static_cast<int64_t>(candidate.point3D_id);
    result->correspondences.push_back(correspondence);
    result->point2D_idxs.push_back(candidate.point2D_idx);
  }
  result->seconds = SecondsSince(start);
  return true;
}

bool MapLocalizer::CollectDatabaseMatches(
    const DatabaseImage& image, const colmap::FeatureDescriptors& descriptors,
    std::vector<CorrespondenceCandidate>* candidates,
    int* num_map_images_matched, std::string* error) const {
  colmap::FeatureMatches matches;
  for (const colmap::image_t map_image_id : map_image_ids_) {
    if (map_image_id == image.image_id) continue;
    if (!database_->ReadInlierMatches(image.image_id, map_image_id, &matches,
                                      error)) {
      return false;
    }
    const std::vector<colmap::point3D_t>& map_point3D_ids =
        map_image_point3D_ids_.at(map_image_id);
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
  if (map_image_ids_.size() <=
      static_cast<size_t>(options_.max_num_map_images_exhaustive)) {
    return map_image_ids_;
  }
  // The map images that observe most of the image's direct matches.
  std::vector<PointDescriptorIndex::PointMatch> matches;
  point_index_.Match(descriptors, options_.sift_matching.max_ratio,
                     options_.sift_matching.max_distance, &matches);
  std::unordered_map<colmap::image_t, int> votes;
  for (const PointDescriptorIndex::PointMatch& match : matches) {
    for (const colmap::image_t image_id :
         map_points_.at(match.point3D_id).image_ids) {
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
  for (const colmap::image_t map_image_id : map_image_ids) {
    if (!database_->ReadDescriptors(map_image_id, &map_descriptors, error)) {
      return false;
    }
    const std::vector<colmap::point3D_t>& map_point3D_ids =
        map_image_point3D_ids_.at(map_image_id);
    colmap::MatchSiftFeaturesCPU(options_.sift_matching, descriptors,
                                 map_descriptors, &matches);
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
