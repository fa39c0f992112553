#include "colmap_ext/report/heat_map_figure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "colmap_ext/report/figure_format.h"
#include "colmap_ext/report/svg_plot.h"

namespace rig_calibrator {
namespace {

std::string Label(const double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3g", value);
  return text;
}

}  // namespace

std::string HeatColor(const double t) {
  // viridis at 0, 0.25, 0.5, 0.75, 1.
  static const double kStops[5][3] = {{68, 1, 84},
                                      {59, 82, 139},
                                      {33, 145, 140},
                                      {94, 201, 98},
                                      {253, 231, 37}};
  const double s = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * 4;
  const int k = std::min(3, static_cast<int>(s));
  const double a = s - k;
  char text[8];
  std::snprintf(text, sizeof(text), "#%02x%02x%02x",
                static_cast<int>(
                    std::lround((1 - a) * kStops[k][0] + a * kStops[k + 1][0])),
                static_cast<int>(
                    std::lround((1 - a) * kStops[k][1] + a * kStops[k + 1][1])),
                static_cast<int>(std::lround((1 - a) * kStops[k][2] +
                                             a * kStops[k + 1][2])));
  return text;
}

std::string ColorBarSvg(const double x, const double y, const double height,
                        const double low, const double high,
                        const std::string& unit) {
  constexpr int kSteps = 16;
  std::ostringstream svg;
  const double step = height / kSteps;
  for (int k = 0; k < kSteps; ++k) {
    svg << "<rect x=\"" << FormatSvgCoordinate(x) << "\" y=\""
        << FormatSvgCoordinate(y + height - (k + 1) * step)
        << "\" width=\"12\" height=\"" << FormatSvgCoordinate(step + 0.5)
        << "\" fill=\"" << HeatColor((k + 0.5) / kSteps) << "\"/>";
  }
  svg << "<rect x=\"" << FormatSvgCoordinate(x) << "\" y=\""
      << FormatSvgCoordinate(y) << "\" width=\"12\" height=\""
      << FormatSvgCoordinate(height) << "\" fill=\"none\" stroke=\"#333\"/>"
      << "<text x=\"" << FormatSvgCoordinate(x + 16) << "\" y=\""
      << FormatSvgCoordinate(y + 10) << "\">" << Label(high) << "</text>"
      << "<text x=\"" << FormatSvgCoordinate(x + 16) << "\" y=\""
      << FormatSvgCoordinate(y + height) << "\">" << Label(low) << "</text>"
      << "<text x=\"" << FormatSvgCoordinate(x + 16) << "\" y=\""
      << FormatSvgCoordinate(y + height / 2 + 4) << "\">" << XmlEscape(unit)
      << "</text>\n";
  return svg.str();
}

std::string HeatMapSvg(const HeatMapOptions& options,
                       const ImageGridValues& grid) {
  const double scale = kImageFigureWidth / std::max(1, options.image_width);
  const double height = options.image_height * scale;
  const double cell_width = kImageFigureWidth / std::max(1, grid.cols);
  const double cell_height = height / std::max(1, grid.rows);
  double high = 0;
  for (const double value : grid.values) {
    if (std::isfinite(value)) high = std::max(high, value);
  }
  std::ostringstream svg;
  svg << "<svg id=\"" << XmlEscape(options.id)
      << "\" xmlns=\"http://www.w3.org/2000/svg\" width=\"380\" height=\""
      << FormatSvgCoordinate(height + kImageFigureTop + 12)
      << "\" font-family=\"sans-serif\" "
      << "font-size=\"11\">\n<text x=\""
      << FormatSvgCoordinate(kImageFigureLeft)
      << "\" y=\"18\" font-size=\"13\">" << XmlEscape(options.title)
      << "</text>\n";
  for (int row = 0; row < grid.rows; ++row) {
    for (int col = 0; col < grid.cols; ++col) {
      const double value = grid.values[row * grid.cols + col];
      svg << "<rect x=\""
          << FormatSvgCoordinate(kImageFigureLeft + col * cell_width)
          << "\" y=\""
          << FormatSvgCoordinate(kImageFigureTop + row * cell_height)
          << "\" width=\"" << FormatSvgCoordinate(cell_width + 0.3)
          << "\" height=\"" << FormatSvgCoordinate(cell_height + 0.3)
          << "\" fill=\""
          << (std::isfinite(value) ? HeatColor(high > 0 ? value / high : 0)
                                   : std::string("#eeeeee"))
          << "\"/>";
    }
    svg << "\n";
  }
  svg << "<rect x=\"" << FormatSvgCoordinate(kImageFigureLeft) << "\" y=\""
      << FormatSvgCoordinate(kImageFigureTop) << "\" width=\""
      << FormatSvgCoordinate(kImageFigureWidth) << "\" height=\""
      << FormatSvgCoordinate(height) << "\" fill=\"none\" stroke=\"#333\"/>\n";
  if (options.marker) {
    const double x = kImageFigureLeft + options.marker->x() * scale;
    const double y = kImageFigureTop + options.marker->y() * scale;
    svg << "<circle cx=\"" << FormatSvgCoordinate(x) << "\" cy=\""
        << FormatSvgCoordinate(y)
        << "\" r=\"6\" fill=\"none\" stroke=\"#d62728\" stroke-width=\"2\"/>"
        << "<text x=\""
        << FormatSvgCoordinate(std::min(x + 8, kImageFigureWidth - 40))
        << "\" y=\""
        << FormatSvgCoordinate(std::max(y - 8, kImageFigureTop + 10))
        << "\" fill=\"#d62728\">" << XmlEscape(options.marker_label)
        << "</text>\n";
  }
  svg << ColorBarSvg(kImageFigureLeft + kImageFigureWidth + 12, kImageFigureTop,
                     std::min(height, 160.0), 0, high, options.unit)
      << "</svg>\n";
  return svg.str();
}

}  // namespace rig_calibrator
