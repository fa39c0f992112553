// The consistency of a COLMAP model as every later stage assumes it,
// checked once on reading (ReadModel): COLMAP 3.8's readers take each file
// as it is, so a model edited by a script, merged from others or written by
// another tool can hold references that lead nowhere, and the stages and the
// output writer follow them with COLMAP's accessors, which throw or abort.
//
// Invariants, and what is done when one is violated:
// * Every camera has a positive width and height, as many parameters as its
//   model has, all finite, and positive focal lengths.
//   Refused: the intrinsics of a map camera are projected with (final
//   adjustment, reprojection errors of the output model); no repair is right.
// * Every image refers to a camera of the model and has a finite pose
//   (quaternion and translation). Refused: the image's observations cannot
//   be used without them.
// * Every observation of an image (a point2D with a POINT3D_ID) refers to a
//   point of the model whose track lists that (image, point2D index), at a
//   finite position in the image. Repaired: the observation is dropped (the
//   point2D stays, without a point) — an observation that its point does not
//   confirm is not a measurement of that point.
// * Every element of a point's track refers to an image of the model, to one
//   of its points2D, which refers back to that point; no element repeats.
//   Repaired: the element is dropped — a track element that its image does
//   not confirm is not an observation the image holds.
// * Every point has a finite position and, after the above, a track.
//   Repaired: the point is dropped with its observations — a point nothing
//   observes, or at no place, cannot serve to localize or to adjust.
// Ids are unique (CheckUniqueModelIds) and COLMAP's invalid ids do not occur
// as ids (the readers refuse kInvalidCameraId; an observation of point id
// kInvalidPoint3DId is read by COLMAP as no observation, and a point with
// that id then has a track no image confirms).
//
// Repairs change the in-memory map only, never the input files, and are
// counted in one warning with an example of each kind, so that the user can
// find and fix the files.
#pragma once

#include <colmap/base/reconstruction.h>

#include <cstdint>
#include <string>

namespace rig_calibrator {

// What CheckMapConsistency repaired; each with one example for the message.
struct MapRepairs {
  int64_t num_dropped_observations = 0;
  std::string dropped_observation_example;
  int64_t num_dropped_track_elements = 0;
  std::string dropped_track_element_example;
  int64_t num_dropped_points = 0;
  std::string dropped_point_example;

  bool Any() const {
    return num_dropped_observations > 0 || num_dropped_track_elements > 0 ||
           num_dropped_points > 0;
  }
  // One line for the user: what was dropped, with the examples, naming the
  // model folder `path`.
  std::string Describe(const std::string& path) const;
};

// Checks `map`, read from the model folder `path` (binary files if `binary`,
// for the file names in messages), against the invariants above: repairs
// what can be repaired and counts it in *repairs, or fails with a message
// naming the file, the image, the camera or the point.
bool CheckMapConsistency(const std::string& path, bool binary,
                         colmap::Reconstruction* map, MapRepairs* repairs,
                         std::string* error);

}  // namespace rig_calibrator
