#include "colmap_ext/report/svg_plot.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <sstream>

namespace rig_calibrator {
namespace {

// Tableau-like palette, readable on white and distinguishable in print.
const char* const kPalette[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e",
                                "#9467bd", "#8c564b", "#e377c2", "#7f7f7f"};
constexpr int kPaletteSize = sizeof(kPalette) / sizeof(kPalette[0]);

// Margins around the plot area, pixels; the legend lives in the right one.
constexpr double kLeftMargin = 70, kTopMargin = 40, kBottomMargin = 55;
constexpr double kSlantedLabelsMargin = 120;
constexpr double kLegendWidth = 170;

std::string Color(size_t index) { return kPalette[index % kPaletteSize]; }

// Shortest readable label of a tick value.
std::string TickLabel(double value) {
  if (std::abs(value) < 1e-12) return "0";
  char text[32];
  std::snprintf(text, sizeof(text), "%g", value);
  return text;
}

// Maps data coordinates to pixels within the plot area.
struct Axes {
  double left = 0, right = 0, top = 0, bottom = 0;  // pixels
  double x_low = 0, x_high = 1, y_low = 0, y_high = 1;
  bool log_x = false;

  double X(double x) const {
    const double a = log_x ? std::log10(x) : x;
    const double low = log_x ? std::log10(x_low) : x_low;
    const double high = log_x ? std::log10(x_high) : x_high;
    return left + (a - low) / (high - low) * (right - left);
  }
  double Y(double y) const {
    return bottom - (y - y_low) / (y_high - y_low) * (bottom - top);
  }
};

std::string Number(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f", value);
  return text;
}

void Header(const PlotOptions& options, std::ostringstream* svg) {
  if (options.inline_id.empty()) {
    *svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg";
  } else {
    *svg << "<svg id=\"" << XmlEscape(options.inline_id) << "\"";
  }
  *svg << " xmlns=\"http://www.w3.org/2000/svg\" width=\"" << options.width
       << "\" height=\"" << options.height << "\" viewBox=\"0 0 "
       << options.width << " " << options.height
       << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
       << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
       << "<text x=\"" << options.width / 2 << "\" y=\"22\" "
       << "text-anchor=\"middle\" font-size=\"15\">" << XmlEscape(options.title)
       << "</text>\n";
}

// Frame, y ticks with grid lines, axis labels.
void AxesFrame(const PlotOptions& options, const Axes& axes,
               const std::vector<double>& y_ticks, std::ostringstream* svg) {
  for (const double tick : y_ticks) {
    const std::string y = Number(axes.Y(tick));
    *svg << "<line x1=\"" << Number(axes.left) << "\" y1=\"" << y << "\" x2=\""
         << Number(axes.right) << "\" y2=\"" << y << "\" stroke=\"#e0e0e0\"/>\n"
         << "<text x=\"" << Number(axes.left - 6) << "\" y=\"" << y
         << "\" text-anchor=\"end\" dominant-baseline=\"middle\">"
         << TickLabel(tick) << "</text>\n";
  }
  *svg << "<rect x=\"" << Number(axes.left) << "\" y=\"" << Number(axes.top)
       << "\" width=\"" << Number(axes.right - axes.left) << "\" height=\""
       << Number(axes.bottom - axes.top)
       << "\" fill=\"none\" stroke=\"black\"/>\n"
       << "<text x=\"" << Number(0.5 * (axes.left + axes.right)) << "\" y=\""
       << Number(options.height - 12) << "\" text-anchor=\"middle\">"
       << XmlEscape(options.x_label) << "</text>\n"
       << "<text transform=\"translate(16 "
       << Number(0.5 * (axes.top + axes.bottom))
       << ") rotate(-90)\" text-anchor=\"middle\">"
       << XmlEscape(options.y_label) << "</text>\n";
}

void XTick(const Axes& axes, double x, const std::string& label, bool slant,
           std::ostringstream* svg) {
  const std::string px = Number(x);
  const std::string py = Number(axes.bottom + 18);
  *svg << "<line x1=\"" << px << "\" y1=\"" << Number(axes.bottom) << "\" x2=\""
       << px << "\" y2=\"" << Number(axes.bottom + 5)
       << "\" stroke=\"black\"/>\n"
       << "<text x=\"" << px << "\" y=\"" << py << "\" text-anchor=\""
       << (slant ? "start" : "middle") << "\"";
  // Slanted down to the right, into the space below the legend.
  if (slant) *svg << " transform=\"rotate(30 " << px << " " << py << ")\"";
  *svg << ">" << XmlEscape(label) << "</text>\n";
}

void Legend(const Axes& axes, const std::vector<std::string>& labels,
            bool as_boxes, std::ostringstream* svg) {
  const double x = axes.right + 15;
  for (size_t s = 0; s < labels.size(); ++s) {
    const double y = axes.top + 10 + 20 * s;
    if (as_boxes) {
      *svg << "<rect x=\"" << Number(x) << "\" y=\"" << Number(y - 6)
           << "\" width=\"20\" height=\"12\" fill=\"" << Color(s) << "\"/>\n";
    } else {
      *svg << "<line x1=\"" << Number(x) << "\" y1=\"" << Number(y)
           << "\" x2=\"" << Number(x + 20) << "\" y2=\"" << Number(y)
           << "\" stroke=\"" << Color(s) << "\" stroke-width=\"2.5\"/>\n";
    }
    *svg << "<text x=\"" << Number(x + 26) << "\" y=\"" << Number(y)
         << "\" dominant-baseline=\"middle\">" << XmlEscape(labels[s])
         << "</text>\n";
  }
}

Axes PlotArea(const PlotOptions& options) {
  Axes axes;
  axes.left = kLeftMargin;
  axes.right = std::max(kLeftMargin + 50, options.width - kLegendWidth);
  axes.top = kTopMargin;
  axes.bottom =
      std::max(kTopMargin + 50,
               options.height - (options.slant_x_labels ? kSlantedLabelsMargin
                                                        : kBottomMargin));
  return axes;
}

// [y_min, y_max] from the options, else [0, max of the data] (1 if none).
void YRange(const PlotOptions& options, double data_max, Axes* axes) {
  axes->y_low = std::isfinite(options.y_min) ? options.y_min : 0.0;
  axes->y_high = std::isfinite(options.y_max)
                     ? options.y_max
                     : (data_max > axes->y_low ? data_max : axes->y_low + 1);
  if (!(axes->y_high > axes->y_low)) axes->y_high = axes->y_low + 1;
}

}  // namespace

std::string XmlEscape(const std::string& text) {
  std::string escaped;
  for (const char c : text) {
    switch (c) {
      case '&':
        escaped += "&amp;";
        break;
      case '<':
        escaped += "&lt;";
        break;
      case '>':
        escaped += "&gt;";
        break;
      case '"':
        escaped += "&quot;";
        break;
      case '\'':
        escaped += "&apos;";
        break;
      default:
        escaped += c;
    }
  }
  return escaped;
}

std::vector<double> LinearTicks(double low, double high, int target) {
  std::vector<double> ticks;
  if (!std::isfinite(low) || !std::isfinite(high) || !(high > low) ||
      target < 1) {
    return ticks;
  }
  // Step = 1, 2 or 5 times 10^k, the smallest giving at most `target` steps.
  const double raw_step = (high - low) / target;
  const double power = std::pow(10.0, std::floor(std::log10(raw_step)));
  double step = 10 * power;
  for (const double factor : {1.0, 2.0, 5.0}) {
    if (factor * power >= raw_step) {
      step = factor * power;
      break;
    }
  }
  for (double k = std::ceil(low / step - 1e-9); k * step <= high + 1e-9 * step;
       ++k) {
    ticks.push_back(std::abs(k) < 0.5 ? 0.0 : k * step);
  }
  return ticks;
}

std::string LinePlotSvg(const PlotOptions& options,
                        const std::vector<PlotSeries>& series) {
  auto usable = [&](double x, double y) {
    return std::isfinite(x) && std::isfinite(y) && (!options.log_x || x > 0);
  };
  double x_low = std::numeric_limits<double>::infinity();
  double x_high = -x_low, y_max = -x_low;
  for (const PlotSeries& s : series) {
    for (size_t k = 0; k < s.x.size() && k < s.y.size(); ++k) {
      if (!usable(s.x[k], s.y[k])) continue;
      x_low = std::min(x_low, s.x[k]);
      x_high = std::max(x_high, s.x[k]);
      y_max = std::max(y_max, s.y[k]);
    }
  }
  Axes axes = PlotArea(options);
  axes.log_x = options.log_x;
  if (std::isfinite(options.x_min)) x_low = options.x_min;
  if (std::isfinite(options.x_max)) x_high = options.x_max;
  if (!std::isfinite(x_low) || !std::isfinite(x_high)) {
    x_low = options.log_x ? 0.1 : 0.0;
    x_high = options.log_x ? 10.0 : 1.0;
  }
  if (options.log_x) {
    // Whole decades, so that the ticks sit at the ends.
    x_low = std::pow(10.0, std::floor(std::log10(x_low)));
    x_high = std::pow(10.0, std::ceil(std::log10(x_high)));
    if (!(x_high > x_low)) x_high = 10 * x_low;
  } else if (!(x_high > x_low)) {
    x_high = x_low + 1;
  }
  axes.x_low = x_low;
  axes.x_high = x_high;
  YRange(options, y_max, &axes);

  std::ostringstream svg;
  Header(options, &svg);
  AxesFrame(options, axes, LinearTicks(axes.y_low, axes.y_high, 5), &svg);
  if (options.log_x) {
    for (double tick = x_low; tick <= x_high * (1 + 1e-9); tick *= 10) {
      XTick(axes, axes.X(tick), TickLabel(tick), options.slant_x_labels, &svg);
    }
  } else {
    for (const double tick : LinearTicks(x_low, x_high, 8)) {
      XTick(axes, axes.X(tick), TickLabel(tick), options.slant_x_labels, &svg);
    }
  }
  for (size_t m = 0; m < options.x_markers.size(); ++m) {
    const double x = options.x_markers[m];
    if (!usable(x, 0) || x < x_low || x > x_high) continue;
    const std::string px = Number(axes.X(x));
    svg << "<line x1=\"" << px << "\" y1=\"" << Number(axes.top) << "\" x2=\""
        << px << "\" y2=\"" << Number(axes.bottom)
        << "\" stroke=\"#555555\" stroke-dasharray=\"5,4\"/>\n";
    if (m < options.x_marker_labels.size()) {
      svg << "<text x=\"" << Number(axes.X(x) + 4) << "\" y=\""
          << Number(axes.top + 14 * (m + 1)) << "\" fill=\"#555555\">"
          << XmlEscape(options.x_marker_labels[m]) << "</text>\n";
    }
  }
  // Data clipped to the plot area.
  const std::string clip_id = options.inline_id.empty()
                                  ? std::string("plot-area")
                                  : XmlEscape(options.inline_id) + "-plot-area";
  svg << "<clipPath id=\"" << clip_id << "\"><rect x=\"" << Number(axes.left)
      << "\" y=\"" << Number(axes.top) << "\" width=\""
      << Number(axes.right - axes.left) << "\" height=\""
      << Number(axes.bottom - axes.top) << "\"/></clipPath>\n";
  std::vector<std::string> labels;
  for (size_t s = 0; s < series.size(); ++s) {
    labels.push_back(series[s].label);
    std::ostringstream points;
    bool first = true;
    double previous_y = 0;
    for (size_t k = 0; k < series[s].x.size() && k < series[s].y.size(); ++k) {
      const double x = series[s].x[k], y = series[s].y[k];
      if (!usable(x, y)) continue;
      if (series[s].step && !first) {
        points << Number(axes.X(x)) << "," << Number(axes.Y(previous_y)) << " ";
      }
      points << Number(axes.X(x)) << "," << Number(axes.Y(y)) << " ";
      previous_y = y;
      first = false;
    }
    if (first) continue;
    svg << "<polyline clip-path=\"url(#" << clip_id
        << ")\" fill=\"none\" stroke=\"" << Color(s)
        << "\" stroke-width=\"2\" points=\"" << points.str() << "\"/>\n";
  }
  Legend(axes, labels, /*as_boxes=*/false, &svg);
  svg << "</svg>\n";
  return svg.str();
}

std::string BarChartSvg(const PlotOptions& options,
                        const std::vector<std::string>& categories,
                        const std::vector<std::string>& series_labels,
                        const std::vector<std::vector<double>>& values) {
  double y_max = 0;
  for (const std::vector<double>& row : values) {
    for (const double value : row) {
      if (std::isfinite(value)) y_max = std::max(y_max, value);
    }
  }
  Axes axes = PlotArea(options);
  YRange(options, y_max, &axes);
  std::ostringstream svg;
  Header(options, &svg);
  AxesFrame(options, axes, LinearTicks(axes.y_low, axes.y_high, 5), &svg);
  const int num_categories = std::max<int>(1, categories.size());
  const double group_width = (axes.right - axes.left) / num_categories;
  const double bar_width =
      0.8 * group_width / std::max<size_t>(1, series_labels.size());
  for (size_t c = 0; c < categories.size(); ++c) {
    const double group_left = axes.left + c * group_width;
    XTick(axes, group_left + 0.5 * group_width, categories[c],
          options.slant_x_labels, &svg);
    for (size_t s = 0; s < values.size() && s < series_labels.size(); ++s) {
      if (c >= values[s].size() || !std::isfinite(values[s][c])) continue;
      const double value = std::clamp(values[s][c], axes.y_low, axes.y_high);
      const double x = group_left + 0.1 * group_width + s * bar_width;
      const double y = axes.Y(value);
      svg << "<rect x=\"" << Number(x) << "\" y=\"" << Number(y)
          << "\" width=\"" << Number(0.9 * bar_width) << "\" height=\""
          << Number(axes.Y(axes.y_low) - y) << "\" fill=\"" << Color(s)
          << "\"><title>" << XmlEscape(series_labels[s]) << ", "
          << XmlEscape(categories[c]) << ": " << TickLabel(values[s][c])
          << "</title></rect>\n";
    }
  }
  Legend(axes, series_labels, /*as_boxes=*/true, &svg);
  svg << "</svg>\n";
  return svg.str();
}

PlotSeries CumulativeDistribution(const std::string& label,
                                  std::vector<double> values) {
  PlotSeries series;
  series.label = label;
  series.step = true;
  const double total = static_cast<double>(values.size());
  values.erase(std::remove_if(values.begin(), values.end(),
                              [](double v) { return !std::isfinite(v); }),
               values.end());
  std::sort(values.begin(), values.end());
  for (size_t k = 0; k < values.size(); ++k) {
    series.x.push_back(values[k]);
    series.y.push_back((k + 1) / total);
  }
  return series;
}

}  // namespace rig_calibrator
