// Reprojection residuals of the rig images, recomputed from an output model
// (observed 2D point minus the projection of its 3D point with the image's
// camera and pose), aggregated for the report: per camera on a grid over the
// image, per image and per frameset. Aggregates, not observations, so the
// report's size does not grow with the number of observations.
#pragma once

#include <colmap/base/reconstruction.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "colmap_ext/io/correspondence_io.h"
#include "colmap_ext/io/rigs_frames_io.h"

namespace rig_calibrator {

// The rig camera the report shows: its images are the model's images whose
// name starts with `image_prefix` (as in calibration_summary.json).
struct ReportCamera {
  std::string name;
  std::string image_prefix;
};

struct ResidualCell {
  double sum_dx = 0, sum_dy = 0;  // residual sums, pixels
  double sum_squared = 0;         // sum of dx^2 + dy^2
  int64_t count = 0;
};

struct CameraResiduals {
  colmap::camera_t camera_id = colmap::kInvalidCameraId;  // none: no image
  // Where the observations come from: the model's observations of its 3D
  // points (the inliers), or, for a camera with none (a calibration from a
  // correspondence file without a map has no 3D points), the rows of
  // correspondences.txt within `inlier_threshold_px` = 3 x the median
  // residual of the camera's rows, at least 0.01 px (for Gaussian noise the
  // median of |r| is 1.18 sigma, so this keeps 99.8 % of the inliers).
  bool from_correspondences = false;
  double inlier_threshold_px = 0;
  int width = 0, height = 0;
  // cols x rows cells of equal size covering the image, row-major from the
  // top-left; an observation at (u, v) is in cell
  // (floor(u / width * cols), floor(v / height * rows)), clamped.
  int cols = 0, rows = 0;
  std::vector<ResidualCell> cells;
  int64_t num_observations = 0;
  double rms_px = 0;        // sqrt(sum |r|^2 / n)
  double max_error_px = 0;  // largest |r|
  // Distance of the observed points from the principal point, pixels.
  double min_radius_px = 0, max_radius_px = 0;
};

struct ImageError {
  std::string name;
  int camera = -1;    // index into the cameras given
  int frameset = -1;  // index into ModelResiduals::framesets
  int64_t num_observations = 0;
  double rms_px = 0;
};

struct FramesetError {
  std::string name;  // the image name without its camera's prefix
  int64_t num_observations = 0;
  double rms_px = 0;
  // Per camera, RMS of its image in the frameset; NaN when it has none.
  std::vector<double> camera_rms_px;
};

struct ModelResiduals {
  std::vector<CameraResiduals> cameras;  // as given
  std::vector<ImageError> images;        // in frameset order, then camera
  std::vector<FramesetError> framesets;
};

// The residuals of every registered image of `cameras` in `model`; of an
// image whose points2D observe no 3D point, those of its rows in
// `correspondences` (the image's points2D are its rows in order; images
// whose row count differs are left out). A
// frameset is a frame of `rigs_frames` holding images of `cameras`, in frame
// id order; without frames, the images with the same name after their
// camera's prefix, in name order. Observations behind their camera are left
// out. `grid_cols` cells across each image, rows in proportion (at least 1).
ModelResiduals ComputeModelResiduals(
    const colmap::Reconstruction& model,
    const std::optional<ColmapRigsAndFrames>& rigs_frames,
    const std::vector<ReportCamera>& cameras, int grid_cols,
    const std::vector<ImageCorrespondences>& correspondences);

}  // namespace rig_calibrator
