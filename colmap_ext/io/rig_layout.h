// Rig discovery from image names: which camera took each image, and which
// images were taken together (a frameset).
//
// Image names are relative to the image path, with '/' (as in a COLMAP
// database). The cameras are the first-level folders ("cam0/", "cam1/", ...)
// or user-given prefixes ("rig/cam0/"). An image's frameset key is its name
// after the camera prefix: identical keys form a frameset (COLMAP's
// convention: cam0/000012.png and cam1/000012.png), or, when the keys are
// numbers such as nanosecond timestamps (EuRoC: 1403715273262142976.png),
// keys within a tolerance do. Or the framesets are given: the frames of a
// COLMAP >= 3.12 database after COLMAP's rig_configurator grouped its images.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace rig_calibrator {

struct RigLayoutOptions {
  // Image name prefixes of the cameras, e.g. {"rig/cam0/", "rig/cam1/"}; an
  // image belongs to the longest prefix it starts with. Empty: every
  // first-level folder of the image names is a camera.
  std::vector<std::string> camera_prefixes;
  // 0: a frameset is the images with identical keys. > 0: keys are numbers
  // (the file name, or the file name without its extension) and images whose
  // numbers are within this tolerance (in the names' units, e.g. nanoseconds)
  // form a frameset, at most one image per camera.
  double timestamp_tolerance = 0;
  // With timestamp_tolerance > 0: remove each camera's constant offset from
  // its names before grouping them (timestamp_offsets.h), so that cameras
  // whose names differ by more than the tolerance still pair. Offsets of
  // about 0 keep the grouping without them exactly.
  bool estimate_timestamp_offsets = true;
  // The reference camera's name (the offsets are relative to it); empty:
  // the first camera.
  std::string reference_camera;
  // Empty, or one per image name: the id of the frame the image is in (e.g.
  // COLMAP's frames/frame_data), -1 for none. Given, the framesets are these
  // frames (an image without one is alone) and timestamp_tolerance is not
  // used.
  std::vector<int64_t> frame_ids;
  // How the given frames are named in the rig table, e.g. "the database's
  // frames (COLMAP rig_configurator)".
  std::string frame_source;
};

struct RigLayoutImage {
  int camera_index = -1;  // -1: the image belongs to no camera (ignored)
  int frameset_index = -1;
};

struct RigLayout {
  // Sorted in natural order (cam2 before cam10). The name is the prefix
  // without its trailing '/'.
  std::vector<std::string> camera_names;
  std::vector<std::string> camera_prefixes;
  // One per frameset, in natural order of the keys (or by time); the key of
  // the frameset's earliest image.
  std::vector<std::string> frameset_names;
  // One per input image name, in input order.
  std::vector<RigLayoutImage> images;
  // Indices of input names that are in no camera (e.g. top-level files).
  std::vector<int> ignored_images;
  // Indices of input names alone in their frameset: they constrain their
  // camera's intrinsics but not the rig.
  std::vector<int> unmatched_images;
  // Where the framesets come from, for the rig table: "identical names after
  // the camera prefix", "timestamps within ...", or the given frame_source.
  std::string frameset_source;
  // With timestamp_tolerance > 0 (and no given frames): per input image its
  // number minus its camera's timestamp offset (below) minus the smallest
  // such number, i.e. on the reference camera's clock (in the names' units;
  // -1 for an ignored image), else empty.
  std::vector<double> image_times;
  // With timestamp_tolerance > 0: per camera the constant removed from its
  // names before grouping (its names minus the reference camera's, names'
  // units; all 0 without estimate_timestamp_offsets), else empty.
  std::vector<double> timestamp_offsets;
  int reference_camera = 0;  // index of RigLayoutOptions::reference_camera
};

// Discovers the cameras and framesets of `image_names` (the rig images only,
// not the map's). Fails with a message in `error` when there are no camera
// folders, fewer than two cameras, a given prefix matches no image, numeric
// keys are expected but a name is not a number, a given frame holds two
// images of one camera, the reference camera is not a camera, or some
// cameras never share a frameset (directly or through other cameras) with
// the others.
bool DiscoverRigLayout(const std::vector<std::string>& image_names,
                       const RigLayoutOptions& options, RigLayout* layout,
                       std::string* error);

// A table for the log, headed by where the framesets come from: per camera
// the number of images, of images in
// framesets with other cameras and of unmatched images; the number of
// framesets with k cameras; the first unmatched and ignored names.
std::string RigLayoutTable(const std::vector<std::string>& image_names,
                           const RigLayout& layout);

// The frameset times (RigDataset::frameset_times_s) of a layout with
// image_times: per frameset the time of its `reference_camera` image, or the
// median of its images' times (timestamp offsets removed: on the reference
// camera's clock) when that camera is not in it, times
// `unit_s` (seconds per name unit, e.g. 1e-9 for nanosecond names); origin
// the earliest image. Empty when the layout has no times or the frameset
// times are not strictly increasing (e.g. framesets of several subfolders,
// which are ordered by folder first).
std::vector<double> FramesetTimes(const RigLayout& layout, int reference_camera,
                                  double unit_s);

// Natural order: digit runs compare as numbers ("cam2" < "cam10").
bool NaturalLess(const std::string& a, const std::string& b);

}  // namespace rig_calibrator
