#include "colmap_ext/report/residual_field_figure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "colmap_ext/report/figure_format.h"
#include "colmap_ext/report/heat_map_figure.h"
#include "colmap_ext/report/svg_plot.h"

namespace rig_calibrator {
namespace {

// An arrow from (x, y) by (dx, dy) pixels of the figure, with a head of a
// quarter of its length (at most 5 pixels).
std::string Arrow(const double x, const double y, const double dx,
                  const double dy, const std::string& color) {
  const double length = std::hypot(dx, dy);
  if (length < 0.5) {
    return "<circle cx=\"" + FormatSvgCoordinate(x) + "\" cy=\"" +
           FormatSvgCoordinate(y) + "\" r=\"1\" fill=\"" + color + "\"/>";
  }
  const double head = std::min(5.0, 0.25 * length);
  const double ux = dx / length, uy = dy / length;
  const double tip_x = x + dx, tip_y = y + dy;
  std::ostringstream path;
  path << "<path d=\"M" << FormatSvgCoordinate(x) << " "
       << FormatSvgCoordinate(y) << "L" << FormatSvgCoordinate(tip_x) << " "
       << FormatSvgCoordinate(tip_y) << "M"
       << FormatSvgCoordinate(tip_x - head * (ux - 0.5 * uy)) << " "
       << FormatSvgCoordinate(tip_y - head * (uy + 0.5 * ux)) << "L"
       << FormatSvgCoordinate(tip_x) << " " << FormatSvgCoordinate(tip_y) << "L"
       << FormatSvgCoordinate(tip_x - head * (ux + 0.5 * uy)) << " "
       << FormatSvgCoordinate(tip_y - head * (uy - 0.5 * ux)) << "\" stroke=\""
       << color << "\" fill=\"none\" stroke-width=\"1.3\"/>";
  return path.str();
}

}  // namespace

std::string ResidualFieldSvg(const std::string& id, const std::string& title,
                             const CameraResiduals& residuals) {
  const double scale = kImageFigureWidth / std::max(1, residuals.width);
  const double height = residuals.height * scale;
  const double cell_width = kImageFigureWidth / std::max(1, residuals.cols);
  const double cell_height = height / std::max(1, residuals.rows);
  double max_mean = 0, max_rms = 0;
  for (const ResidualCell& cell : residuals.cells) {
    if (cell.count == 0) continue;
    max_mean = std::max(max_mean, std::hypot(cell.sum_dx, cell.sum_dy) /
                                      static_cast<double>(cell.count));
    max_rms = std::max(max_rms, std::sqrt(cell.sum_squared / cell.count));
  }
  // Figure pixels per pixel of residual.
  const double arrow_scale =
      max_mean > 0 ? 0.9 * std::min(cell_width, cell_height) / max_mean : 0;
  std::ostringstream svg;
  svg << "<svg id=\"" << XmlEscape(id)
      << "\" xmlns=\"http://www.w3.org/2000/svg\" width=\"380\" height=\""
      << FormatSvgCoordinate(height + kImageFigureTop + 34)
      << "\" font-family=\"sans-serif\" "
      << "font-size=\"11\">\n<text x=\""
      << FormatSvgCoordinate(kImageFigureLeft)
      << "\" y=\"18\" font-size=\"13\">" << XmlEscape(title) << "</text>\n";
  svg << "<rect x=\"" << FormatSvgCoordinate(kImageFigureLeft) << "\" y=\""
      << FormatSvgCoordinate(kImageFigureTop) << "\" width=\""
      << FormatSvgCoordinate(kImageFigureWidth) << "\" height=\""
      << FormatSvgCoordinate(height) << "\" fill=\"#eeeeee\"/>\n";
  for (int row = 0; row < residuals.rows; ++row) {
    for (int col = 0; col < residuals.cols; ++col) {
      const ResidualCell& cell = residuals.cells[row * residuals.cols + col];
      if (cell.count == 0) continue;
      const double rms = std::sqrt(cell.sum_squared / cell.count);
      const double x = kImageFigureLeft + col * cell_width;
      const double y = kImageFigureTop + row * cell_height;
      svg << "<rect x=\"" << FormatSvgCoordinate(x) << "\" y=\""
          << FormatSvgCoordinate(y) << "\" width=\""
          << FormatSvgCoordinate(cell_width + 0.3) << "\" height=\""
          << FormatSvgCoordinate(cell_height + 0.3) << "\" fill=\""
          << HeatColor(max_rms > 0 ? rms / max_rms : 0)
          << "\" fill-opacity=\"0.55\"/>"
          << Arrow(x + 0.5 * cell_width, y + 0.5 * cell_height,
                   arrow_scale * cell.sum_dx / cell.count,
                   arrow_scale * cell.sum_dy / cell.count, "#000000")
          << "\n";
    }
  }
  svg << "<rect x=\"" << FormatSvgCoordinate(kImageFigureLeft) << "\" y=\""
      << FormatSvgCoordinate(kImageFigureTop) << "\" width=\""
      << FormatSvgCoordinate(kImageFigureWidth) << "\" height=\""
      << FormatSvgCoordinate(height) << "\" fill=\"none\" stroke=\"#333\"/>\n";
  const double legend_y = kImageFigureTop + height + 20;
  if (arrow_scale > 0) {
    const double legend_px = NiceBelow(max_mean);
    svg << Arrow(kImageFigureLeft, legend_y - 4, arrow_scale * legend_px, 0,
                 "#000000")
        << "<text x=\""
        << FormatSvgCoordinate(kImageFigureLeft + arrow_scale * legend_px + 6)
        << "\" y=\"" << FormatSvgCoordinate(legend_y) << "\">mean residual "
        << legend_px << " px</text>\n";
  } else {
    svg << "<text x=\"" << FormatSvgCoordinate(kImageFigureLeft) << "\" y=\""
        << FormatSvgCoordinate(legend_y) << "\">no residuals</text>\n";
  }
  svg << ColorBarSvg(kImageFigureLeft + kImageFigureWidth + 12, kImageFigureTop,
                     std::min(height, 160.0), 0, max_rms, "RMS px")
      << "</svg>\n";
  return svg.str();
}

}  // namespace rig_calibrator
