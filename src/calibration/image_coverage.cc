#include "src/calibration/image_coverage.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace rig_calibrator {

ImageCoverage ComputeImageCoverage(
    const colmap::Camera& camera,
    const std::vector<Eigen::Vector2d>& points2D) {
  ImageCoverage coverage;
  const double width = static_cast<double>(camera.Width());
  const double height = static_cast<double>(camera.Height());
  const double longer = std::max(width, height);
  const int shorter_cells = std::max(
      1, static_cast<int>(
             std::lround(kGridCells * std::min(width, height) / longer)));
  coverage.grid_cols = width >= height ? kGridCells : shorter_cells;
  coverage.grid_rows = width >= height ? shorter_cells : kGridCells;
  coverage.counts.assign(coverage.grid_cols * coverage.grid_rows, 0);

  const Eigen::Vector2d principal_point(camera.PrincipalPointX(),
                                        camera.PrincipalPointY());
  for (const Eigen::Vector2d& corner :
       {Eigen::Vector2d(0, 0), Eigen::Vector2d(width, 0),
        Eigen::Vector2d(0, height), Eigen::Vector2d(width, height)}) {
    coverage.corner_radius_px =
        std::max(coverage.corner_radius_px, (corner - principal_point).norm());
  }
  for (const Eigen::Vector2d& point : points2D) {
    if (!point.allFinite() || point.x() < 0 || point.y() < 0 ||
        point.x() >= width || point.y() >= height) {
      continue;
    }
    const int col =
        std::min(coverage.grid_cols - 1,
                 static_cast<int>(point.x() / width * coverage.grid_cols));
    const int row =
        std::min(coverage.grid_rows - 1,
                 static_cast<int>(point.y() / height * coverage.grid_rows));
    ++coverage.counts[row * coverage.grid_cols + col];
    ++coverage.num_points;
    coverage.max_observed_radius_px = std::max(
        coverage.max_observed_radius_px, (point - principal_point).norm());
  }
  const int num_covered = static_cast<int>(
      std::count_if(coverage.counts.begin(), coverage.counts.end(),
                    [](const int count) { return count > 0; }));
  coverage.fraction_cells =
      static_cast<double>(num_covered) / coverage.counts.size();
  coverage.radius_ratio =
      coverage.corner_radius_px > 0
          ? coverage.max_observed_radius_px / coverage.corner_radius_px
          : 0;
  return coverage;
}

bool IsPoorCoverage(const ImageCoverage& coverage, std::string* why) {
  std::ostringstream text;
  text.precision(3);
  if (coverage.radius_ratio < kMinRadiusRatio) {
    text << "the observations reach " << coverage.max_observed_radius_px
         << " px from the principal point, " << 100 * coverage.radius_ratio
         << " % of the corner radius " << coverage.corner_radius_px
         << " px (below " << 100 * kMinRadiusRatio
         << " %): the distortion beyond is extrapolated";
  }
  if (coverage.fraction_cells < kMinFractionCells) {
    text << (text.tellp() > 0 ? "; " : "") << "observations in "
         << 100 * coverage.fraction_cells << " % of the " << coverage.grid_cols
         << "x" << coverage.grid_rows << " image cells (below "
         << 100 * kMinFractionCells << " %)";
  }
  *why = text.str();
  return !why->empty();
}

}  // namespace rig_calibrator
