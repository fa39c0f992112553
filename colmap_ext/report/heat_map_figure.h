// A value per cell of a grid over a camera's image, drawn as an image-shaped
// heat map with a colour bar (report.html: the coverage of the image by the
// inliers, the 1-sigma projection uncertainty).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace rig_calibrator {

// cols x rows values, row-major from the top-left cell; NaN: no value (drawn
// light grey).
struct ImageGridValues {
  int cols = 0, rows = 0;
  std::vector<double> values;
};

struct HeatMapOptions {
  std::string id;  // the <svg> element's id, unique within the page
  std::string title;
  std::string unit;  // of the colour bar, e.g. "px", "inliers"
  int image_width = 0, image_height = 0;  // pixels of the camera image
  // A point to mark (image pixels), e.g. where the largest value is.
  std::optional<Eigen::Vector2d> marker;
  std::string marker_label;
};

// Colour of t in [0, 1] (clamped) on the viridis colour map (dark blue, green,
// yellow), linear between 5 of its stops: ordered in lightness, readable for
// colour-blind readers and in grey.
std::string HeatColor(double t);

// Where the image goes in the report's image-shaped figures: the image is
// scaled to kImageFigureWidth pixels, kept in proportion.
inline constexpr double kImageFigureWidth = 300;
inline constexpr double kImageFigureLeft = 10, kImageFigureTop = 30;

// A vertical colour bar from `low` (bottom) to `high` (top) at (x, y),
// labelled with both ends and `unit`: SVG elements, no <svg> around them.
std::string ColorBarSvg(double x, double y, double height, double low,
                        double high, const std::string& unit);

// The heat map; the colour range is [0, max value] (all values >= 0).
// Requires values.size() == cols * rows.
std::string HeatMapSvg(const HeatMapOptions& options,
                       const ImageGridValues& grid);

}  // namespace rig_calibrator
