#include "colmap_ext/io/rig_layout.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <sstream>
#include <unordered_set>

#include "colmap_ext/io/timestamp_offsets.h"

namespace rig_calibrator {
namespace {

bool IsDigit(char c) { return c >= '0' && c <= '9'; }

// A frameset key split for timestamp matching: keys in different folders
// below the camera prefix never match.
struct TimedKey {
  std::string folder;
  long double time = 0;
};

// The number a key's file name stands for: the whole file name, or the file
// name without its extension. Only plain decimal numbers (digits with at most
// one '.') count. long double keeps nanosecond timestamps (19 digits) exact.
bool ParseTimedKey(const std::string& key, TimedKey* timed) {
  const size_t slash = key.rfind('/');
  timed->folder = slash == std::string::npos ? "" : key.substr(0, slash + 1);
  const std::string file =
      slash == std::string::npos ? key : key.substr(slash + 1);
  auto parse = [](const std::string& text, long double* value) {
    if (text.empty() || text.front() == '.' || text.back() == '.' ||
        std::count(text.begin(), text.end(), '.') > 1 ||
        !std::all_of(text.begin(), text.end(),
                     [](char c) { return IsDigit(c) || c == '.'; })) {
      return false;
    }
    *value = std::strtold(text.c_str(), nullptr);
    return true;
  };
  if (parse(file, &timed->time)) {
    return true;
  }
  const size_t dot = file.rfind('.');
  return dot != std::string::npos && parse(file.substr(0, dot), &timed->time);
}

std::string CameraList(const std::vector<std::string>& prefixes,
                       const std::vector<int>& indices) {
  std::string list;
  for (const int index : indices) {
    list += (list.empty() ? "" : ", ") + prefixes[index];
  }
  return list;
}

int FindRoot(std::vector<int>* parents, int i) {
  while ((*parents)[i] != i) {
    (*parents)[i] = (*parents)[(*parents)[i]];
    i = (*parents)[i];
  }
  return i;
}

// When every image name is a number (a timestamp): " The closest images of
// two of the groups are A and B, D apart: if they were taken together, set
// --RigCalibrator.timestamp_tolerance to at least D." The smallest
// difference between two sets of numbers is between neighbours in their
// merged sorted order, so one pass over the sorted timestamps finds it.
std::string ClosestTimestampsHint(const std::vector<std::string>& image_names,
                                  const std::vector<std::string>& keys,
                                  const RigLayout& layout,
                                  const std::vector<int>& group_of) {
  std::map<std::string, std::vector<std::pair<long double, int>>> by_folder;
  for (size_t i = 0; i < image_names.size(); ++i) {
    if (layout.images[i].camera_index < 0) continue;
    TimedKey timed;
    if (!ParseTimedKey(keys[i], &timed)) return "";
    by_folder[timed.folder].emplace_back(timed.time, static_cast<int>(i));
  }
  long double best = -1;
  int best_a = -1, best_b = -1;
  for (auto& [folder, times] : by_folder) {
    std::sort(times.begin(), times.end());
    for (size_t k = 1; k < times.size(); ++k) {
      const int a = times[k - 1].second, b = times[k].second;
      if (group_of[layout.images[a].camera_index] ==
          group_of[layout.images[b].camera_index]) {
        continue;
      }
      const long double difference = times[k].first - times[k - 1].first;
      if (best < 0 || difference < best) {
        best = difference;
        best_a = a;
        best_b = b;
      }
    }
  }
  if (best_a < 0) return "";
  std::ostringstream hint;
  hint.precision(19);
  hint << " The closest images of two of the groups are " << image_names[best_a]
       << " and " << image_names[best_b] << ", " << best
       << " apart (in the names' units): if they were taken together, set "
          "--RigCalibrator.timestamp_tolerance to at least that.";
  return hint.str();
}

// Fails unless every camera shares a frameset with the others, directly or
// through other cameras: cam_from_rig of a camera outside the reference
// camera's group cannot be determined.
bool CheckCamerasConnected(const std::vector<std::string>& image_names,
                           const std::vector<std::string>& keys,
                           const RigLayout& layout, std::string* error) {
  const int num_cameras = static_cast<int>(layout.camera_names.size());
  std::vector<std::vector<int>> frameset_cameras(layout.frameset_names.size());
  for (const RigLayoutImage& image : layout.images) {
    if (image.camera_index >= 0) {
      frameset_cameras[image.frameset_index].push_back(image.camera_index);
    }
  }
  std::vector<int> parents(num_cameras);
  std::iota(parents.begin(), parents.end(), 0);
  for (const std::vector<int>& cameras : frameset_cameras) {
    for (size_t i = 1; i < cameras.size(); ++i) {
      parents[FindRoot(&parents, cameras[i])] = FindRoot(&parents, cameras[0]);
    }
  }
  std::map<int, std::vector<int>> groups;
  for (int c = 0; c < num_cameras; ++c) {
    groups[FindRoot(&parents, c)].push_back(c);
  }
  if (groups.size() == 1) {
    return true;
  }
  std::ostringstream message;
  message << "the cameras fall into " << groups.size()
          << " groups that never share a frameset:";
  for (const auto& group : groups) {
    message << " {" << CameraList(layout.camera_prefixes, group.second) << "}";
  }
  message << "; framesets are images with the same name after the camera "
             "prefix, or with numeric names within "
             "--RigCalibrator.timestamp_tolerance.";
  std::vector<int> group_of(num_cameras);
  for (const auto& [root, cameras] : groups) {
    for (const int camera : cameras) group_of[camera] = root;
  }
  message << ClosestTimestampsHint(image_names, keys, layout, group_of);
  message << " Name the images so that the images taken together have the "
             "same name in every camera folder (e.g. cam0/000012.png and "
             "cam1/000012.png), or give a tolerance for timestamp names";
  *error = message.str();
  return false;
}

// Greedy clustering of one folder's timestamps, sorted by time: a frameset
// starts at its earliest image and takes the following images within
// `tolerance` of it, until one is too late or its camera is already present.
// Every frameset thus spans at most `tolerance`.
std::vector<std::vector<int>> ClusterTimestamps(
    std::vector<int> images, const std::vector<TimedKey>& keys,
    const std::vector<RigLayoutImage>& layout_images, long double tolerance) {
  std::sort(images.begin(), images.end(), [&](int a, int b) {
    if (keys[a].time != keys[b].time) {
      return keys[a].time < keys[b].time;
    }
    return layout_images[a].camera_index < layout_images[b].camera_index;
  });
  std::vector<std::vector<int>> clusters;
  std::unordered_set<int> cluster_cameras;
  long double start_time = 0;
  for (const int image : images) {
    const int camera = layout_images[image].camera_index;
    if (clusters.empty() || keys[image].time - start_time > tolerance ||
        cluster_cameras.count(camera) > 0) {
      clusters.emplace_back();
      cluster_cameras.clear();
      start_time = keys[image].time;
    }
    clusters.back().push_back(image);
    cluster_cameras.insert(camera);
  }
  return clusters;
}

// False with "<an_item> is empty" or "<the_item> <name> <twice>" unless
// every name is non-empty and given once.
bool CheckUniqueAndNonEmpty(const std::vector<std::string>& names,
                            const std::string& an_item,
                            const std::string& the_item,
                            const std::string& twice, std::string* error) {
  std::unordered_set<std::string> unique_names;
  for (const std::string& name : names) {
    if (name.empty()) {
      *error = an_item + " is empty";
      return false;
    }
    if (!unique_names.insert(name).second) {
      *error = the_item + " " + name + " " + twice;
      return false;
    }
  }
  return true;
}

// The camera prefixes, given or (default) the first-level folders of the
// image names, in natural order.
bool CameraPrefixes(const std::vector<std::string>& image_names,
                    const RigLayoutOptions& options,
                    std::vector<std::string>* camera_prefixes,
                    std::string* error) {
  std::vector<std::string>& prefixes = *camera_prefixes;
  prefixes = options.camera_prefixes;
  if (prefixes.empty()) {
    std::unordered_set<std::string> folders;
    for (const std::string& name : image_names) {
      const size_t slash = name.find('/');
      if (slash != std::string::npos && slash > 0) {
        folders.insert(name.substr(0, slash + 1));
      }
    }
    if (folders.empty()) {
      *error = "no camera folders: none of the " +
               std::to_string(image_names.size()) +
               " image names is in a folder; put each camera's images in its "
               "own folder (cam0/..., cam1/...) or give the camera prefixes";
      return false;
    }
    prefixes.assign(folders.begin(), folders.end());
  } else if (!CheckUniqueAndNonEmpty(prefixes, "a camera prefix",
                                     "the camera prefix", "is given twice",
                                     error)) {
    return false;
  }
  std::sort(prefixes.begin(), prefixes.end(), NaturalLess);
  return true;
}

// Each image's camera (the longest matching prefix; images of none are
// ignored) and its key, the name after the prefix; fails for a camera
// without images and for fewer than two cameras.
bool AssignCameras(const std::vector<std::string>& image_names,
                   const std::vector<std::string>& prefixes, RigLayout* layout,
                   std::vector<std::string>* image_keys, std::string* error) {
  const int num_cameras = static_cast<int>(prefixes.size());
  std::vector<std::string>& keys = *image_keys;
  layout->images.resize(image_names.size());
  std::vector<int> camera_num_images(num_cameras, 0);
  keys.assign(image_names.size(), std::string());
  for (size_t i = 0; i < image_names.size(); ++i) {
    const std::string& name = image_names[i];
    int best = -1;
    for (int c = 0; c < num_cameras; ++c) {
      if (name.size() > prefixes[c].size() &&
          name.compare(0, prefixes[c].size(), prefixes[c]) == 0 &&
          (best < 0 || prefixes[c].size() > prefixes[best].size())) {
        best = c;
      }
    }
    if (best < 0) {
      layout->ignored_images.push_back(static_cast<int>(i));
      continue;
    }
    layout->images[i].camera_index = best;
    keys[i] = name.substr(prefixes[best].size());
    ++camera_num_images[best];
  }
  for (int c = 0; c < num_cameras; ++c) {
    if (camera_num_images[c] == 0) {
      *error = "the camera prefix " + prefixes[c] + " matches no image";
      return false;
    }
  }
  if (num_cameras < 2) {
    *error = "a rig needs at least two cameras: found only " + prefixes[0] +
             " (" + std::to_string(camera_num_images[0]) +
             " images); put each camera's images in its own folder (cam0/, "
             "cam1/, ...) or give the camera prefixes";
    return false;
  }
  layout->camera_prefixes = prefixes;
  for (const std::string& prefix : prefixes) {
    layout->camera_names.push_back(
        prefix.back() == '/' ? prefix.substr(0, prefix.size() - 1) : prefix);
  }
  return true;
}

// The given frames as framesets (an image without a frame alone), in
// natural order of their first image's key; fails for a frame with two
// images of one camera.
bool GroupGivenFrames(const std::vector<std::string>& image_names,
                      const std::vector<std::string>& keys,
                      const RigLayoutOptions& options, const RigLayout& layout,
                      std::vector<std::vector<int>>* framesets,
                      std::string* error) {
  if (options.frame_ids.size() != image_names.size()) {
    *error = "one frame id per image name is needed";
    return false;
  }
  std::map<int64_t, std::vector<int>> frame_images;
  for (size_t i = 0; i < image_names.size(); ++i) {
    if (layout.images[i].camera_index < 0) continue;
    if (options.frame_ids[i] < 0) {
      framesets->push_back({static_cast<int>(i)});
      continue;
    }
    std::vector<int>& images = frame_images[options.frame_ids[i]];
    for (const int other : images) {
      if (layout.images[other].camera_index == layout.images[i].camera_index) {
        *error = "frame " + std::to_string(options.frame_ids[i]) + " of " +
                 options.frame_source + " holds two images of camera " +
                 layout.camera_prefixes[layout.images[i].camera_index] + " (" +
                 image_names[other] + ", " + image_names[i] +
                 "): give camera prefixes that match the cameras of the "
                 "frames";
        return false;
      }
    }
    images.push_back(static_cast<int>(i));
  }
  for (auto& entry : frame_images)
    framesets->push_back(std::move(entry.second));
  std::sort(framesets->begin(), framesets->end(),
            [&](const std::vector<int>& a, const std::vector<int>& b) {
              return NaturalLess(keys[a.front()], keys[b.front()]);
            });
  return true;
}

// The framesets, each a list of input indices: the images with the same key,
// or (timestamp_tolerance > 0) the clusters of close timestamps per folder,
// each camera's timestamp offset removed. With timestamps, also each image's
// time and the offsets (RigLayout::image_times, timestamp_offsets).
bool GroupFramesets(const std::vector<std::string>& image_names,
                    const std::vector<std::string>& keys,
                    const RigLayoutOptions& options, const RigLayout& layout,
                    std::vector<std::vector<int>>* framesets,
                    std::vector<double>* image_times,
                    std::vector<double>* timestamp_offsets,
                    std::string* error) {
  if (!options.frame_ids.empty()) {
    return GroupGivenFrames(image_names, keys, options, layout, framesets,
                            error);
  }
  if (options.timestamp_tolerance > 0) {
    std::vector<TimedKey> timed_keys(image_names.size());
    std::map<std::string, std::vector<int>> folder_images;
    for (size_t i = 0; i < image_names.size(); ++i) {
      if (layout.images[i].camera_index < 0) continue;
      if (!ParseTimedKey(keys[i], &timed_keys[i])) {
        *error = "timestamp_tolerance is set but the image " + image_names[i] +
                 " has no numeric name (expected e.g. " +
                 layout.camera_prefixes[layout.images[i].camera_index] +
                 "1403715273262142976.png)";
        return false;
      }
      folder_images[timed_keys[i].folder].push_back(static_cast<int>(i));
    }
    // Each camera's offset removed from its names (timestamp_offsets.h).
    std::map<std::string, int> folder_ids;
    std::vector<TimedName> names;
    for (size_t i = 0; i < image_names.size(); ++i) {
      if (layout.images[i].camera_index < 0) continue;
      const auto folder = folder_ids.emplace(timed_keys[i].folder,
                                             static_cast<int>(folder_ids.size()));
      names.push_back({layout.images[i].camera_index, folder.first->second,
                       timed_keys[i].time});
    }
    const int num_cameras = static_cast<int>(layout.camera_names.size());
    const std::vector<long double> offsets =
        options.estimate_timestamp_offsets
            ? EstimateTimestampOffsets(names, num_cameras,
                                       layout.reference_camera,
                                       options.timestamp_tolerance)
            : std::vector<long double>(num_cameras, 0);
    timestamp_offsets->assign(offsets.begin(), offsets.end());
    for (size_t i = 0; i < image_names.size(); ++i) {
      if (layout.images[i].camera_index >= 0) {
        timed_keys[i].time -= offsets[layout.images[i].camera_index];
      }
    }
    // Relative to the earliest name, so that the differences of 19-digit
    // nanosecond stamps keep their precision as doubles.
    long double earliest = std::numeric_limits<long double>::infinity();
    for (size_t i = 0; i < image_names.size(); ++i) {
      if (layout.images[i].camera_index >= 0) {
        earliest = std::min(earliest, timed_keys[i].time);
      }
    }
    image_times->assign(image_names.size(), -1.0);
    for (size_t i = 0; i < image_names.size(); ++i) {
      if (layout.images[i].camera_index >= 0) {
        (*image_times)[i] = static_cast<double>(timed_keys[i].time - earliest);
      }
    }
    std::vector<std::string> folders;
    for (const auto& entry : folder_images) folders.push_back(entry.first);
    std::sort(folders.begin(), folders.end(), NaturalLess);
    for (const std::string& folder : folders) {
      for (std::vector<int>& cluster :
           ClusterTimestamps(folder_images[folder], timed_keys, layout.images,
                             options.timestamp_tolerance)) {
        framesets->push_back(std::move(cluster));
      }
    }
  } else {
    std::map<std::string, std::vector<int>> key_images;
    for (size_t i = 0; i < image_names.size(); ++i) {
      if (layout.images[i].camera_index >= 0) {
        key_images[keys[i]].push_back(static_cast<int>(i));
      }
    }
    std::vector<std::string> sorted_keys;
    for (const auto& entry : key_images) sorted_keys.push_back(entry.first);
    std::sort(sorted_keys.begin(), sorted_keys.end(), NaturalLess);
    for (const std::string& key : sorted_keys) {
      framesets->push_back(key_images[key]);
    }
  }
  return true;
}

// The index of options.reference_camera (default: the first camera).
bool FindReferenceCamera(const RigLayoutOptions& options, RigLayout* layout,
                         std::string* error) {
  layout->reference_camera = 0;
  if (options.reference_camera.empty()) return true;
  const auto it = std::find(layout->camera_names.begin(),
                            layout->camera_names.end(),
                            options.reference_camera);
  if (it == layout->camera_names.end()) {
    *error = "--RigCalibrator.reference_camera " + options.reference_camera +
             " is not a camera of the rig";
    return false;
  }
  layout->reference_camera = static_cast<int>(it - layout->camera_names.begin());
  return true;
}

// Names the framesets after their first image's key (unique), sets each
// image's frameset and lists the images alone in their frameset.
void NameFramesets(const std::vector<std::string>& keys,
                   const std::vector<std::vector<int>>& framesets,
                   RigLayout* layout) {
  std::unordered_set<std::string> frameset_names;
  for (size_t f = 0; f < framesets.size(); ++f) {
    // Keys are unique in the exact mode; with timestamps two framesets can
    // start with equal keys of different cameras, and a suffix keeps the
    // names unique.
    std::string name = keys[framesets[f].front()];
    for (int copy = 2; !frameset_names.insert(name).second; ++copy) {
      name = keys[framesets[f].front()] + "~" + std::to_string(copy);
    }
    layout->frameset_names.push_back(name);
    for (const int image : framesets[f]) {
      layout->images[image].frameset_index = static_cast<int>(f);
    }
    if (framesets[f].size() == 1) {
      layout->unmatched_images.push_back(framesets[f].front());
    }
  }
  std::sort(layout->unmatched_images.begin(), layout->unmatched_images.end());
}

}  // namespace

bool NaturalLess(const std::string& a, const std::string& b) {
  size_t i = 0;
  size_t j = 0;
  while (i < a.size() && j < b.size()) {
    if (IsDigit(a[i]) && IsDigit(b[j])) {
      size_t i_end = i;
      size_t j_end = j;
      while (i_end < a.size() && IsDigit(a[i_end])) ++i_end;
      while (j_end < b.size() && IsDigit(b[j_end])) ++j_end;
      // Compare the runs as numbers: without leading zeros, the longer run is
      // the larger number; equal lengths compare digit by digit.
      size_t i_digits = i;
      size_t j_digits = j;
      while (i_digits + 1 < i_end && a[i_digits] == '0') ++i_digits;
      while (j_digits + 1 < j_end && b[j_digits] == '0') ++j_digits;
      const size_t a_length = i_end - i_digits;
      const size_t b_length = j_end - j_digits;
      if (a_length != b_length) {
        return a_length < b_length;
      }
      const int order = a.compare(i_digits, a_length, b, j_digits, b_length);
      if (order != 0) {
        return order < 0;
      }
      i = i_end;
      j = j_end;
    } else {
      if (a[i] != b[j]) {
        return a[i] < b[j];
      }
      ++i;
      ++j;
    }
  }
  if (i < a.size() || j < b.size()) {
    return j < b.size();
  }
  // Equal as numbers ("01" and "1"): fall back to plain order, so that the
  // order stays strict.
  return a < b;
}

std::vector<double> FramesetTimes(const RigLayout& layout,
                                  const int reference_camera,
                                  const double unit_s) {
  if (layout.image_times.size() != layout.images.size() || !(unit_s > 0)) {
    return {};
  }
  std::vector<std::vector<double>> frameset_image_times(
      layout.frameset_names.size());
  std::vector<std::optional<double>> reference_times(
      layout.frameset_names.size());
  for (size_t i = 0; i < layout.images.size(); ++i) {
    const RigLayoutImage& image = layout.images[i];
    if (image.camera_index < 0 || image.frameset_index < 0) continue;
    frameset_image_times[image.frameset_index].push_back(
        layout.image_times[i]);
    if (image.camera_index == reference_camera) {
      reference_times[image.frameset_index] = layout.image_times[i];
    }
  }
  std::vector<double> times;
  for (size_t f = 0; f < frameset_image_times.size(); ++f) {
    std::vector<double>& image_times = frameset_image_times[f];
    if (image_times.empty()) return {};
    std::sort(image_times.begin(), image_times.end());
    const size_t n = image_times.size();
    const double median = (image_times[(n - 1) / 2] + image_times[n / 2]) / 2;
    times.push_back(reference_times[f].value_or(median) * unit_s);
    // Names beyond long double's range parse as infinite.
    if (!std::isfinite(times[f]) || (f > 0 && !(times[f] > times[f - 1]))) {
      return {};
    }
  }
  return times;
}

bool DiscoverRigLayout(const std::vector<std::string>& image_names,
                       const RigLayoutOptions& options, RigLayout* layout,
                       std::string* error) {
  *layout = RigLayout();
  if (!(options.timestamp_tolerance >= 0) ||
      !std::isfinite(options.timestamp_tolerance)) {
    *error = "timestamp_tolerance must be a finite number >= 0";
    return false;
  }
  if (!CheckUniqueAndNonEmpty(image_names, "an image name", "the image name",
                              "appears twice", error)) {
    return false;
  }
  std::vector<std::string> prefixes;
  std::vector<std::string> keys;
  std::vector<std::vector<int>> framesets;
  if (!CameraPrefixes(image_names, options, &prefixes, error) ||
      !AssignCameras(image_names, prefixes, layout, &keys, error) ||
      !FindReferenceCamera(options, layout, error) ||
      !GroupFramesets(image_names, keys, options, *layout, &framesets,
                      &layout->image_times, &layout->timestamp_offsets,
                      error)) {
    return false;
  }
  NameFramesets(keys, framesets, layout);
  if (!options.frame_ids.empty()) {
    layout->frameset_source = options.frame_source;
  } else if (options.timestamp_tolerance > 0) {
    std::ostringstream source;
    source << "numeric names (timestamps) within "
           << options.timestamp_tolerance;
    if (std::any_of(layout->timestamp_offsets.begin(),
                    layout->timestamp_offsets.end(),
                    [](double offset) { return offset != 0; })) {
      source << " after removing each camera's timestamp offset";
    }
    layout->frameset_source = source.str();
  } else {
    layout->frameset_source = "identical names after the camera prefix";
  }
  if (!CheckCamerasConnected(image_names, keys, *layout, error)) {
    // Timestamps with constant offsets between cameras pair once the
    // offsets are removed.
    if (options.frame_ids.empty() && options.timestamp_tolerance > 0 &&
        !options.estimate_timestamp_offsets) {
      *error +=
          "; or, if the cameras' names differ by a constant, let "
          "--RigCalibrator.timestamp_offsets auto remove it";
    }
    *layout = RigLayout();
    return false;
  }
  return true;
}

std::string RigLayoutTable(const std::vector<std::string>& image_names,
                           const RigLayout& layout) {
  const int num_cameras = static_cast<int>(layout.camera_names.size());
  std::vector<int> frameset_sizes(layout.frameset_names.size(), 0);
  for (const RigLayoutImage& image : layout.images) {
    if (image.camera_index >= 0) ++frameset_sizes[image.frameset_index];
  }
  std::vector<int> num_images(num_cameras, 0);
  std::vector<int> num_matched(num_cameras, 0);
  for (const RigLayoutImage& image : layout.images) {
    if (image.camera_index < 0) continue;
    ++num_images[image.camera_index];
    if (frameset_sizes[image.frameset_index] > 1) {
      ++num_matched[image.camera_index];
    }
  }
  size_t name_width = 6;
  for (const std::string& prefix : layout.camera_prefixes) {
    name_width = std::max(name_width, prefix.size());
  }

  std::ostringstream table;
  table << "Rig layout: " << num_cameras << " cameras, "
        << layout.frameset_names.size() << " framesets (from "
        << layout.frameset_source << ")\n";
  auto pad = [](const std::string& text, size_t width) {
    return text +
           std::string(width > text.size() ? width - text.size() : 0, ' ');
  };
  auto right = [](const std::string& text, size_t width) {
    return std::string(width > text.size() ? width - text.size() : 0, ' ') +
           text;
  };
  table << "  " << pad("camera", name_width) << "  " << right("images", 8)
        << "  " << right("with other cameras", 18) << "  "
        << right("unmatched", 9) << "\n";
  for (int c = 0; c < num_cameras; ++c) {
    table << "  " << pad(layout.camera_prefixes[c], name_width) << "  "
          << right(std::to_string(num_images[c]), 8) << "  "
          << right(std::to_string(num_matched[c]), 18) << "  "
          << right(std::to_string(num_images[c] - num_matched[c]), 9) << "\n";
  }
  std::vector<int> histogram(num_cameras + 1, 0);
  for (const int size : frameset_sizes) ++histogram[size];
  table << "  framesets with k cameras:";
  for (int k = 1; k <= num_cameras; ++k) {
    table << " " << k << ": " << histogram[k] << (k < num_cameras ? "," : "");
  }
  table << "\n";
  constexpr size_t kMaxListed = 10;
  auto list = [&](const char* title, const std::vector<int>& indices) {
    if (indices.empty()) return;
    table << "  " << indices.size() << " " << title << ":";
    for (size_t i = 0; i < std::min(indices.size(), kMaxListed); ++i) {
      table << " " << image_names[indices[i]];
    }
    table << (indices.size() > kMaxListed ? " ...\n" : "\n");
  };
  if (std::any_of(layout.timestamp_offsets.begin(),
                  layout.timestamp_offsets.end(),
                  [](double offset) { return offset != 0; })) {
    table << "  timestamp offsets removed before grouping (names minus "
          << layout.camera_names[layout.reference_camera]
          << "'s, names' units):";
    table.precision(12);
    for (int c = 0; c < num_cameras; ++c) {
      table << " " << layout.camera_names[c] << " " << std::showpos
            << layout.timestamp_offsets[c] << std::noshowpos
            << (c + 1 < num_cameras ? "," : "\n");
    }
  }
  list("unmatched images (alone in their frameset)", layout.unmatched_images);
  list("ignored images (in no camera)", layout.ignored_images);
  return table.str();
}

}  // namespace rig_calibrator
