#include "colmap_ext/lab_commands/robustness_figures.h"

#include <algorithm>

#include "colmap_ext/report/svg_plot.h"

namespace rig_calibrator {

std::string ErrorDistributionSvg(const RobustnessCell& cell, bool rotation,
                                 bool final_errors) {
  PlotOptions options;
  options.title = std::string(final_errors ? "Final" : "Initial") + " " +
                  (rotation ? "rotation" : "translation") + " errors, " +
                  cell.spec.Label();
  options.x_label = rotation ? "rotation error (deg), log scale"
                             : "camera center error (cm), log scale";
  options.y_label = "fraction of cameras";
  options.log_x = true;
  options.y_min = 0;
  options.y_max = 1;
  options.x_markers = {rotation ? 1.0
                                : 100 * cell.spec.scene.good_center_error};
  options.x_marker_labels = {"good"};
  std::vector<PlotSeries> series;
  for (const ShortSequenceResult& result : cell.results) {
    std::vector<double> values =
        rotation ? (final_errors ? result.final_rotation_deg
                                 : result.initial_rotation_deg)
                 : (final_errors ? result.final_center_error
                                 : result.initial_center_error);
    if (!rotation) {
      for (double& value : values) value *= 100;
    }
    // Exact zeros (the reference camera's center) cannot sit on a log axis:
    // they are drawn at the axis minimum.
    for (double& value : values) value = std::max(value, 1e-4);
    std::string label = CalibrationMethodName(result.method);
    if (result.num_fallbacks > 0) label += " (rd_ra)";
    series.push_back(CumulativeDistribution(label, std::move(values)));
  }
  return LinePlotSvg(options, series);
}

std::string GoodCalibrationsSvg(const std::vector<RobustnessCell>& cells) {
  PlotOptions options;
  options.title = "Short sequences calibrated well (paper Table 3)";
  options.x_label = "rig / scene / difficulty";
  options.y_label = "good calibrations (%)";
  options.y_min = 0;
  options.y_max = 100;
  options.width = std::max(720, 70 * static_cast<int>(cells.size()) + 240);
  options.height = 480;
  options.slant_x_labels = true;
  std::vector<std::string> categories, methods;
  std::vector<std::vector<double>> values;
  for (const RobustnessCell& cell : cells) {
    categories.push_back(RigPresetName(cell.spec.preset) + " " +
                         cell.spec.scene.name.substr(0, 3) + " " +
                         cell.spec.difficulty.name);
    for (size_t m = 0; m < cell.results.size(); ++m) {
      if (values.size() <= m) {
        values.emplace_back();
        methods.push_back(CalibrationMethodName(cell.results[m].method));
      }
      values[m].push_back(cell.results[m].PercentGood());
    }
  }
  return BarChartSvg(options, categories, methods, values);
}

}  // namespace rig_calibrator
