// Internal to the rig initialization (rig_init_problem.h): which images,
// framesets and cameras a set of images determines, given the rotations.
//
// A frameset's rig translation t_Q is determined by one full pose, or by the
// radial rows of two or more cameras whose principal axes z_k (rig frame)
// make sum_k (I - z_k z_k^T) regular (AxesDetermineTranslation with
// kMinDeterminingAxisAngleDeg, principal_axes.h; parallel and anti-parallel
// axes alike are not enough). A camera needs
// images in such framesets, and all camera translations together must be
// determined relative to an anchor camera (TranslationsDetermined, through
// the reduced system of rig_init_translations.h).
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "src/calibration/rig_init_problem.h"

namespace rig_calibrator {
namespace rig_init {

// Per localized image / frameset / camera: 1 if determined.
struct DeterminedParts {
  std::vector<char> images;
  std::vector<char> framesets;
  std::vector<char> cameras;
};

// The determined parts among usable_images (restricted to cameras with a
// rotation): framesets determined as in the header, cameras with
// min_images_per_camera images in such framesets, images of both;
// repeated until stable, because dropping a camera can undetermine a
// frameset.
DeterminedParts FindDeterminedParts(
    const InitProblem& problem,
    const std::vector<std::optional<Eigen::Quaterniond>>& cam_from_rig,
    const std::vector<char>& usable_images, int min_images_per_camera);

// FindDeterminedParts, restricted further to the cameras whose translations
// the images determine. Every frameset being determined is not enough: e.g.
// a radial camera only ever seen with one other camera can slide along that
// camera's axis. An undetermined direction of the whole system mixes with
// the gauge and cannot say which cameras it moves, so the determined set is
// grown from the anchor instead: a camera joins if the images of the joined
// cameras and its own determine all their translations. The anchor camera,
// whose t_P is held, is preferred_anchor if kept, else the first kept
// camera; *anchor = num_cameras if none is kept.
DeterminedParts FindTranslationDeterminedParts(
    const InitProblem& problem,
    const std::vector<std::optional<Eigen::Quaterniond>>& cam_rotations,
    const std::vector<std::optional<Eigen::Quaterniond>>& rig_rotations,
    std::vector<char> usable_images, int min_images_per_camera,
    int preferred_anchor, int* anchor);

}  // namespace rig_init
}  // namespace rig_calibrator
