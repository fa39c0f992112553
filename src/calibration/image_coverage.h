// Which part of a camera's image its observations (the final inliers)
// cover. A calibration is determined only where there are data: beyond the
// largest observed radius the distortion is extrapolated (a polynomial
// r (1 + k1 r^2 + k2 r^4) grows like r^5 there and can fold back), and an
// image covered on one side only leaves the principal point and the
// distortion's asymmetry to the model.
//
//  - Grid: kGridCells cells along the longer image side and
//    max(1, round(kGridCells * shorter / longer)) along the shorter one, so
//    the cells are about square (640x480: 10x8, 1920x1080: 10x6); a cell is
//    covered when an observation falls in it. fraction_cells = covered /
//    all.
//  - Radii from the principal point c: max_observed_radius_px =
//    max_k |x_k - c|, corner_radius_px = the farthest image corner's
//    distance max |corner - c| (corners (0,0), (w,0), (0,h), (w,h) in
//    COLMAP's pixel convention), radius_ratio = their ratio.
//
// Poor coverage (IsPoorCoverage), a warning:
//  - radius_ratio < kMinRadiusRatio = 0.8: the corners beyond 0.8 of the
//    corner radius (for a 4:3 image the parts outside the circle through
//    the middle of the left and right edges, 10 % of the image) project with
//    an extrapolated distortion;
//  - fraction_cells < kMinFractionCells = 0.5: half the image has no
//    observation.
#pragma once

#include <colmap/base/camera.h>

#include <Eigen/Core>
#include <string>
#include <vector>

namespace rig_calibrator {

constexpr int kGridCells = 10;
constexpr double kMinRadiusRatio = 0.8;
constexpr double kMinFractionCells = 0.5;

struct ImageCoverage {
  int grid_cols = 0;
  int grid_rows = 0;
  std::vector<int> counts;  // grid_rows * grid_cols, row-major
  int num_points = 0;       // observations inside the image
  double fraction_cells = 0;
  double max_observed_radius_px = 0;
  double corner_radius_px = 0;
  double radius_ratio = 0;
};

// The coverage of `camera`'s image (its size and principal point) by
// `points2D` (pixels, COLMAP convention); points outside the image or not
// finite are ignored. Requires a camera with a positive width and height.
ImageCoverage ComputeImageCoverage(
    const colmap::Camera& camera, const std::vector<Eigen::Vector2d>& points2D);

// Whether the coverage is poor (see above); *why gets the numbers and what
// they mean, empty when it is not.
bool IsPoorCoverage(const ImageCoverage& coverage, std::string* why);

}  // namespace rig_calibrator
