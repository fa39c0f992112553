#include "colmap_ext/report/rig_view_figure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "colmap_ext/report/figure_format.h"
#include "colmap_ext/report/svg_plot.h"

namespace rig_calibrator {
namespace {

constexpr double kSize = 340;   // square drawing area, pixels
constexpr double kMargin = 40;  // around it, for labels
constexpr double kTitle = 24;   // title line above

// The two rig coordinates a view shows, as (right, up) on the page.
Eigen::Vector2d Project(const RigView view, const Eigen::Vector3d& point) {
  return view == RigView::kFromAbove ? Eigen::Vector2d(point.x(), point.z())
                                     : Eigen::Vector2d(point.z(), -point.y());
}

}  // namespace

RigViewFigure RigViewSvg(const std::string& id, const RigView view,
                         const std::vector<RigViewCamera>& cameras,
                         const std::string& units) {
  // Axis length: a quarter of the rig's extent (a tenth of a unit for a
  // single camera).
  double extent = 0;
  for (const RigViewCamera& a : cameras) {
    for (const RigViewCamera& b : cameras) {
      extent = std::max(extent, (a.center_in_rig - b.center_in_rig).norm());
    }
  }
  const double axis_length = extent > 0 ? 0.25 * extent : 0.1;
  Eigen::Vector2d low = Eigen::Vector2d::Constant(1e300);
  Eigen::Vector2d high = -low;
  for (const RigViewCamera& camera : cameras) {
    const Eigen::Vector2d center = Project(view, camera.center_in_rig);
    low = low.cwiseMin(center);
    high = high.cwiseMax(center);
    for (int axis = 0; axis < 3; ++axis) {
      const Eigen::Vector2d tip =
          Project(view, camera.center_in_rig +
                            axis_length * camera.rig_from_cam.col(axis));
      low = low.cwiseMin(tip);
      high = high.cwiseMax(tip);
    }
  }
  if (cameras.empty()) low = high = Eigen::Vector2d::Zero();
  const double span = std::max((high - low).maxCoeff(), 1e-9);
  const double scale = kSize / span;  // pixels per map unit
  const Eigen::Vector2d middle = 0.5 * (low + high);
  const auto page = [&](const Eigen::Vector3d& point) {
    const Eigen::Vector2d p = Project(view, point) - middle;
    return Eigen::Vector2d(kMargin + kSize / 2 + scale * p.x(),
                           kTitle + kMargin + kSize / 2 - scale * p.y());
  };

  RigViewFigure figure;
  std::ostringstream svg;
  const double width = kSize + 2 * kMargin;
  const double height = kSize + 2 * kMargin + kTitle + 10;
  svg << "<svg id=\"" << XmlEscape(id)
      << "\" xmlns=\"http://www.w3.org/2000/svg\" width=\""
      << FormatSvgCoordinate(width) << "\" height=\""
      << FormatSvgCoordinate(height)
      << "\" font-family=\"sans-serif\" font-size=\"11\">\n"
      << "<text x=\"10\" y=\"18\" font-size=\"13\">"
      << (view == RigView::kFromAbove
              ? "From above (x right, z forward up the page)"
              : "From the side (z forward right, y down)")
      << "</text>\n";
  static const char* const kAxisColors[3] = {"#d62728", "#2ca02c", "#1f77b4"};
  for (const RigViewCamera& camera : cameras) {
    const Eigen::Vector2d center = page(camera.center_in_rig);
    if (camera.center_stddev) {
      const Eigen::Vector2d radii =
          scale * Project(view, *camera.center_stddev).cwiseAbs();
      if (radii.maxCoeff() >= 1) {
        svg << "<ellipse cx=\"" << FormatSvgCoordinate(center.x()) << "\" cy=\""
            << FormatSvgCoordinate(center.y()) << "\" rx=\""
            << FormatSvgCoordinate(radii.x()) << "\" ry=\""
            << FormatSvgCoordinate(radii.y())
            << "\" fill=\"#ff7f0e\" fill-opacity=\"0.3\" stroke=\"#ff7f0e\"/>";
      } else {
        figure.ellipses_too_small.push_back(camera.name);
      }
    }
    for (int axis = 0; axis < 3; ++axis) {
      const Eigen::Vector2d tip = page(
          camera.center_in_rig + axis_length * camera.rig_from_cam.col(axis));
      svg << "<line x1=\"" << FormatSvgCoordinate(center.x()) << "\" y1=\""
          << FormatSvgCoordinate(center.y()) << "\" x2=\""
          << FormatSvgCoordinate(tip.x()) << "\" y2=\""
          << FormatSvgCoordinate(tip.y()) << "\" stroke=\"" << kAxisColors[axis]
          << "\" stroke-width=\"" << (axis == 2 ? 2.5 : 1.5) << "\"/>";
    }
    svg << "<circle cx=\"" << FormatSvgCoordinate(center.x()) << "\" cy=\""
        << FormatSvgCoordinate(center.y())
        << "\" r=\"3\" fill=\"black\"/><text x=\""
        << FormatSvgCoordinate(center.x() + 5) << "\" y=\""
        << FormatSvgCoordinate(center.y() - 5) << "\">"
        << XmlEscape(camera.name) << "</text>\n";
  }
  // Scale bar and axis colours.
  const double bar = NiceBelow(0.4 * span);
  const double bar_y = height - 12;
  svg << "<line x1=\"10\" y1=\"" << FormatSvgCoordinate(bar_y) << "\" x2=\""
      << FormatSvgCoordinate(10 + bar * scale) << "\" y2=\""
      << FormatSvgCoordinate(bar_y)
      << "\" stroke=\"black\" stroke-width=\"2\"/><text x=\""
      << FormatSvgCoordinate(14 + bar * scale) << "\" y=\""
      << FormatSvgCoordinate(bar_y + 4) << "\">" << bar << " "
      << XmlEscape(units) << "</text>"
      << "<text x=\"" << FormatSvgCoordinate(width - 10) << "\" y=\""
      << FormatSvgCoordinate(bar_y + 4)
      << "\" text-anchor=\"end\"><tspan fill=\"" << kAxisColors[0]
      << "\">x</tspan> <tspan fill=\"" << kAxisColors[1]
      << "\">y</tspan> <tspan fill=\"" << kAxisColors[2]
      << "\">z (optical axis)</tspan></text>\n</svg>\n";
  figure.svg = svg.str();
  return figure;
}

}  // namespace rig_calibrator
