#include "colmap_ext/report/capture_timing_figure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "colmap_ext/report/figure_format.h"
#include "colmap_ext/report/svg_plot.h"

namespace rig_calibrator {
namespace {

std::string Fixed(const double value, const int decimals,
                  const bool sign = false) {
  char text[48];
  std::snprintf(text, sizeof(text), sign ? "%+.*f" : "%.*f", decimals,
                value + 0.0);
  return text;
}

}  // namespace

std::string CaptureTimingSvg(const std::string& id, const std::string& title,
                             const std::string& unit,
                             const std::vector<TimingFigurePoint>& points) {
  // One row per camera, the value axis horizontal: x = value, y = row.
  constexpr int kWidth = 640, kLeft = 90, kRight = 170, kTop = 40;
  constexpr int kRowHeight = 28, kBottom = 48;
  const int height =
      kTop + kRowHeight * static_cast<int>(points.size()) + kBottom;
  const double plot_right = kWidth - kRight;
  // The axis covers every value, its +-3 sigma bar and zero. A sigma that
  // could not be computed (NaN) has no bars and reads "?".
  double low = 0, high = 0;
  for (const TimingFigurePoint& point : points) {
    const double reach = std::isfinite(point.sigma) ? 3 * point.sigma : 0;
    low = std::min(low, point.value - reach);
    high = std::max(high, point.value + reach);
  }
  if (!(high > low)) {
    low = -1;
    high = 1;
  }
  const std::vector<double> ticks = LinearTicks(low, high, 6);
  low = std::min(low, ticks.front());
  high = std::max(high, ticks.back());
  auto x_of = [&](double value) {
    return FormatSvgCoordinate(kLeft + (value - low) / (high - low) *
                                           (plot_right - kLeft));
  };
  const double plot_bottom = kTop + kRowHeight * points.size();

  std::ostringstream svg;
  svg << "<svg id=\"" << XmlEscape(id)
      << "\" xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kWidth
      << "\" height=\"" << height << "\" viewBox=\"0 0 " << kWidth << " "
      << height << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      << "<text x=\"" << kWidth / 2 << "\" y=\"22\" text-anchor=\"middle\" "
      << "font-size=\"15\">" << XmlEscape(title) << "</text>\n";
  for (const double tick : ticks) {
    const std::string x = x_of(tick);
    svg << "<line x1=\"" << x << "\" y1=\"" << kTop << "\" x2=\"" << x
        << "\" y2=\"" << plot_bottom << "\" stroke=\""
        << (tick == 0 ? "#444\" stroke-dasharray=\"4 3" : "#e0e0e0")
        << "\"/>\n<text x=\"" << x << "\" y=\"" << plot_bottom + 16
        << "\" text-anchor=\"middle\">" << tick << "</text>\n";
  }
  svg << "<text x=\"" << (kLeft + plot_right) / 2 << "\" y=\""
      << plot_bottom + 36 << "\" text-anchor=\"middle\">" << XmlEscape(unit)
      << "</text>\n";
  for (size_t k = 0; k < points.size(); ++k) {
    const TimingFigurePoint& point = points[k];
    const std::string y = FormatSvgCoordinate(kTop + kRowHeight * (k + 0.5));
    const std::string text_y =
        FormatSvgCoordinate(kTop + kRowHeight * (k + 0.5) + 4);
    svg << "<text x=\"" << kLeft - 8 << "\" y=\"" << text_y
        << "\" text-anchor=\"end\">" << XmlEscape(point.camera) << "</text>\n";
    const bool has_sigma = std::isfinite(point.sigma);
    if (has_sigma) {
      svg << "<line class=\"sigma3\" x1=\""
          << x_of(point.value - 3 * point.sigma) << "\" y1=\"" << y
          << "\" x2=\"" << x_of(point.value + 3 * point.sigma) << "\" y2=\""
          << y << "\" stroke=\"#1f77b4\" stroke-width=\"1.5\"/>\n"
          << "<line class=\"sigma1\" x1=\"" << x_of(point.value - point.sigma)
          << "\" y1=\"" << y << "\" x2=\"" << x_of(point.value + point.sigma)
          << "\" y2=\"" << y << "\" stroke=\"#1f77b4\" stroke-width=\"6\"/>\n";
    }
    svg << "<circle cx=\"" << x_of(point.value) << "\" cy=\"" << y
        << "\" r=\"4\" fill=\"#d62728\"/>\n"
        << "<text class=\"value\" x=\"" << plot_right + 10 << "\" y=\""
        << text_y << "\">" << Fixed(point.value, 2, true) << " \u00b1 "
        << (has_sigma ? Fixed(point.sigma, 2) : std::string("?")) << " "
        << XmlEscape(unit) << "</text>\n";
  }
  svg << "</svg>";
  return svg.str();
}

}  // namespace rig_calibrator
