#include "colmap_ext/localization/map_localizer.h"

#include <colmap/util/timer.h>
#include <glog/logging.h>
#include <omp.h>

#include <algorithm>
#include <atomic>

#include "colmap_ext/io/name_table.h"

namespace rig_calibrator {
namespace {

// What to do about a rig image or its features missing from the database.
constexpr char kFeatureExtractorHint[] =
    ": run colmap feature_extractor on the rig images into this database "
    "first (see README)";

std::string MissingImageMessage(const DatabaseReader& database,
                                const std::string& name) {
  return "the database " + database.path() + " has no image named " + name +
         kFeatureExtractorHint;
}

const NameTable<LocalizationMode>& LocalizationModeNames() {
  static const NameTable<LocalizationMode> names = {
      {LocalizationMode::kDirect, "direct"},
      {LocalizationMode::kRetrieval, "retrieval"}};
  return names;
}

}  // namespace

bool LocalizationModeFromName(const std::string& name, LocalizationMode* mode) {
  return ValueFromName(LocalizationModeNames(), name, mode);
}

std::string LocalizationModeName(const LocalizationMode mode) {
  return NameOfValue(LocalizationModeNames(), mode, "unknown");
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
  if (guidance.batch_size < 1 || guidance.min_pose_inliers < 5 ||
      !(guidance.max_line_distance_px > 0) ||
      !(guidance.max_ratio > 0 && guidance.max_ratio <= 1)) {
    return fail(
        "guidance needs batch_size >= 1, min_pose_inliers >= 5, "
        "max_line_distance_px > 0 and max_ratio in (0, 1]");
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
  colmap::Timer timer;
  timer.Start();
  if (!ReadLocalizationMap(map, *database, &localizer->map_, error) ||
      !IndexTrackDescriptors(
          localizer->map_, *database, options.max_descriptors_per_point,
          localizer->NumThreads(), &localizer->point_index_, error)) {
    return nullptr;
  }
  localizer->has_database_matches_ = database->NumVerifiedImagePairs() > 0;

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
            << "; ready in " << timer.ElapsedSeconds() << " s";
  return localizer;
}

bool MapLocalizer::CheckImageFeatures(const DatabaseImage& image,
                                      std::string* error) const {
  const int num_keypoints = database_->NumKeypoints(image.image_id);
  const int num_descriptors = database_->NumDescriptors(image.image_id);
  const std::string hint = kFeatureExtractorHint;
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
    if (map_.image_point3D_ids.count(image->image_id) > 0) {
      LOG(WARNING) << "Rig image " << image->name
                   << " is also a registered map image; it will match its "
                      "own map points";
    }
  }

  const int num_images = static_cast<int>(images.size());
  results->assign(num_images, ImageLocalization());
  std::vector<std::string> errors(num_images);
  std::atomic<int> num_done(0);
  colmap::Timer timer;
  timer.Start();
#pragma omp parallel for schedule(dynamic, 1) num_threads(NumThreads())
  for (int i = 0; i < num_images; ++i) {
    LocalizeImage(*images[i], &(*results)[i], &errors[i]);
    const int done = ++num_done;
    if (options_.progress_interval > 0 &&
        (done % options_.progress_interval == 0 || done == num_images)) {
      const double seconds = timer.ElapsedSeconds();
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
            << timer.ElapsedSeconds() << " s: " << num_correspondences
            << " 2D-3D correspondences, " << num_empty << " images without any";
  return true;
}

bool MapLocalizer::LocalizeImage(const DatabaseImage& image,
                                 ImageLocalization* result,
                                 std::string* error) const {
  colmap::Timer timer;
  timer.Start();
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
      if (!MatchDirectly(image, keypoints, descriptors, &candidates, result,
                         error)) {
        return false;
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
    correspondence.point3D = map_.points.at(candidate.point3D_id).xyz;
    correspondence.point3D_id = static_cast<int64_t>(candidate.point3D_id);
    result->correspondences.push_back(correspondence);
    result->point2D_idxs.push_back(candidate.point2D_idx);
  }
  result->seconds = timer.ElapsedSeconds();
  return true;
}

}  // namespace rig_calibrator
