// Reprojection errors of a COLMAP model recomputed from its own cameras,
// poses and points (the errors COLMAP stores per point are whatever the
// model's writer last set; these are what COLMAP's bundle_adjuster would
// compute).
#pragma once

#include <colmap/base/reconstruction.h>

#include <cstdint>
#include <unordered_set>

namespace rig_calibrator {

// Statistics of |pi(P X) - x| (pixels) over a set of observations.
struct ReprojectionStats {
  int64_t num_observations = 0;
  double mean_px = 0;
  double max_px = 0;
  int64_t num_above_4px = 0;
};

// The reprojection error of `point3D`'s observation `element` (infinite
// behind the camera). The point is the track's own, not the one the image's
// point2D names: on a model read from files the two can differ
// (map_consistency.h repairs that on reading), and the track is what the
// error belongs to. The element's image and point2D must be in `model`.
double ObservationError(const colmap::Reconstruction& model,
                        const colmap::Point3D& point3D,
                        const colmap::TrackElement& element);

// Over every observation of a point by the images in `image_ids` (all
// registered images if empty).
ReprojectionStats ComputeReprojectionStats(
    const colmap::Reconstruction& model,
    const std::unordered_set<colmap::image_t>& image_ids = {});

// Sets every point's error to the mean of its observations' reprojection
// errors, COLMAP's definition (Point3D::Error; model_analyzer's mean
// reprojection error is the mean of these over the points). Observations by
// `excluded_image_ids` (images whose camera this build cannot project) are
// left out; a point seen only by them keeps its error.
void RecomputePointErrors(
    colmap::Reconstruction* model,
    const std::unordered_set<colmap::image_t>& excluded_image_ids = {});

}  // namespace rig_calibrator
