// Small, dependency-free SVG charts for the benchmark reports: line plots
// (e.g. cumulative distributions of errors, paper Fig. 6) and grouped bar
// charts (e.g. the share of good calibrations per method, paper Table 3).
// Every chart has axes with ticks and tick labels, axis labels, a title and a
// legend to the right of the plot area (so it never hides data).
#pragma once

#include <cmath>
#include <string>
#include <vector>

namespace rig_calibrator {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;  // same length; non-finite points are skipped
  // Draw as a staircase (horizontal, then vertical), as for an empirical
  // cumulative distribution.
  bool step = false;
};

struct PlotOptions {
  std::string title, x_label, y_label;
  // Logarithmic x axis (ticks at powers of ten); points with x <= 0 are
  // skipped.
  bool log_x = false;
  int width = 720, height = 420;  // whole picture, pixels
  // Axis ranges; NaN: from the data (x) or [0, max] (y).
  double x_min = std::nan(""), x_max = std::nan("");
  double y_min = std::nan(""), y_max = std::nan("");
  // Optional vertical reference lines (e.g. a "good" threshold), drawn dashed
  // and labelled (one label a line lower than the previous, so that labels of
  // close markers do not overlap).
  std::vector<double> x_markers;
  std::vector<std::string> x_marker_labels;
  // Slanted x tick labels (long category names), with room below the axis.
  bool slant_x_labels = false;
  // Non-empty: the chart is inlined in an HTML page (e.g. report.html) rather
  // than a file of its own: no XML declaration, and this id on the <svg>
  // element and as the prefix of its internal ids, which must be unique
  // within the page.
  std::string inline_id;
};

// A line plot of the series, colors from a fixed palette in series order.
std::string LinePlotSvg(const PlotOptions& options,
                        const std::vector<PlotSeries>& series);

// Bars: values[s][c] is series s (legend) in category c (x axis); NaN values
// are left out. Uses title, x_label, y_label, width, height, y_min/y_max.
std::string BarChartSvg(const PlotOptions& options,
                        const std::vector<std::string>& categories,
                        const std::vector<std::string>& series_labels,
                        const std::vector<std::vector<double>>& values);

// The empirical cumulative distribution of `values` as a step series: the
// fraction of all values (non-finite ones, e.g. failed runs, count in the
// denominator but are never reached) that are <= x.
PlotSeries CumulativeDistribution(const std::string& label,
                                  std::vector<double> values);

// "Nice" tick positions (1, 2 or 5 times a power of ten) covering [low, high]
// with about `target` ticks; exposed for tests.
std::vector<double> LinearTicks(double low, double high, int target);

// Escapes &, <, >, " and ' for SVG text and attributes.
std::string XmlEscape(const std::string& text);

}  // namespace rig_calibrator
