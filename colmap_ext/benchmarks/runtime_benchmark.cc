#include "colmap_ext/benchmarks/runtime_benchmark.h"

#include <colmap/util/math.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "colmap_ext/benchmarks/table_cells.h"
#include "colmap_ext/report/svg_plot.h"

namespace rig_calibrator {
namespace {

constexpr char kCalibrationHeader[] = "rig_calibrator calibration runtime";
constexpr char kLocalizationHeader[] = "rig_calibrator localization runtime";

// One line of text (newlines would break the line-based format).
std::string OneLine(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  std::replace(text.begin(), text.end(), '\r', ' ');
  return text;
}

// Key-value lines after a header line; "key rest of the line".
class Fields {
 public:
  bool Parse(const std::string& text, const std::string& header,
             std::string* error) {
    std::istringstream stream(text);
    std::string line;
    if (!std::getline(stream, line) || line != header) {
      *error =
          "not a serialized result (expected the header \"" + header + "\")";
      return false;
    }
    while (std::getline(stream, line)) {
      if (line.empty()) continue;
      const size_t space = line.find(' ');
      const std::string key = line.substr(0, space);
      const std::string value =
          space == std::string::npos ? "" : line.substr(space + 1);
      if (key == "stage") {
        stages_.push_back(value);
      } else {
        values_[key] = value;
      }
    }
    return true;
  }

  bool Number(const std::string& key, double* value, std::string* error) {
    const auto it = values_.find(key);
    if (it == values_.end()) {
      *error = "missing field " + key;
      return false;
    }
    std::istringstream stream(it->second);
    if (!(stream >> *value)) {
      *error = "field " + key + " is not a number: " + it->second;
      return false;
    }
    return true;
  }

  template <typename Integer>
  bool Integral(const std::string& key, Integer* value, std::string* error) {
    double number = 0;
    if (!Number(key, &number, error)) return false;
    *value = static_cast<Integer>(std::llround(number));
    return true;
  }

  std::string Text(const std::string& key) const {
    const auto it = values_.find(key);
    return it == values_.end() ? "" : it->second;
  }

  const std::vector<std::string>& stages() const { return stages_; }

 private:
  std::map<std::string, std::string> values_;
  std::vector<std::string> stages_;
};

// Stage names over all runs, in order of first appearance.
std::vector<std::string> StageNames(
    const std::vector<CalibrationRuntime>& runs) {
  std::vector<std::string> names;
  for (const CalibrationRuntime& run : runs) {
    for (const StageRuntime& stage : run.stages) {
      if (std::find(names.begin(), names.end(), stage.stage) == names.end()) {
        names.push_back(stage.stage);
      }
    }
  }
  return names;
}

// Wall and CPU seconds and solver iterations of a stage in a run (NaN
// seconds if it did not run); a stage that ran twice (a fallback) counts
// with its total.
struct StageTotals {
  double seconds = 0, cpu_seconds = 0;
  int num_iterations = 0;
};
StageTotals StageSeconds(const CalibrationRuntime& run,
                         const std::string& name) {
  StageTotals totals;
  bool found = false;
  for (const StageRuntime& stage : run.stages) {
    if (stage.stage != name) continue;
    totals.seconds += stage.seconds;
    totals.cpu_seconds += stage.cpu_seconds;
    totals.num_iterations += stage.num_iterations;
    found = true;
  }
  if (!found) totals.seconds = totals.cpu_seconds = std::nan("");
  return totals;
}

std::set<int> CameraCounts(const std::vector<CalibrationRuntime>& runs) {
  std::set<int> counts;
  for (const CalibrationRuntime& run : runs) counts.insert(run.num_cameras);
  return counts;
}

}  // namespace

CalibrationRuntime MedianCalibrationRuntime(
    const std::vector<CalibrationRuntime>& runs) {
  if (runs.empty()) return CalibrationRuntime();
  for (const CalibrationRuntime& run : runs) {
    if (!run.success) return run;
  }
  CalibrationRuntime median = runs.front();
  const auto median_of = [&](const auto& value_of) {
    std::vector<double> values;
    for (const CalibrationRuntime& run : runs) values.push_back(value_of(run));
    return colmap::Median(values);
  };
  median.seconds = median_of([](const auto& run) { return run.seconds; });
  median.cpu_seconds =
      median_of([](const auto& run) { return run.cpu_seconds; });
  median.generation_seconds =
      median_of([](const auto& run) { return run.generation_seconds; });
  for (const CalibrationRuntime& run : runs) {
    median.peak_memory_mb = std::max(median.peak_memory_mb, run.peak_memory_mb);
  }
  // Stages by name: every run of one build has the same stages.
  for (StageRuntime& stage : median.stages) {
    const auto stage_of = [&](const CalibrationRuntime& run) {
      for (const StageRuntime& other : run.stages) {
        if (other.stage == stage.stage) return other;
      }
      return StageRuntime();
    };
    stage.seconds = median_of(
        [&](const CalibrationRuntime& run) { return stage_of(run).seconds; });
    stage.cpu_seconds = median_of([&](const CalibrationRuntime& run) {
      return stage_of(run).cpu_seconds;
    });
  }
  return median;
}

std::string SerializeCalibrationRuntime(const CalibrationRuntime& runtime) {
  std::ostringstream text;
  text << std::setprecision(10) << kCalibrationHeader << "\n"
       << "num_framesets " << runtime.num_framesets << "\n"
       << "num_cameras " << runtime.num_cameras << "\n"
       << "num_images " << runtime.num_images << "\n"
       << "num_correspondences " << runtime.num_correspondences << "\n"
       << "generation_seconds " << runtime.generation_seconds << "\n"
       << "seconds " << runtime.seconds << "\n"
       << "cpu_seconds " << runtime.cpu_seconds << "\n"
       << "peak_memory_mb " << runtime.peak_memory_mb << "\n"
       << "success " << (runtime.success ? 1 : 0) << "\n"
       << "final_rms_px " << runtime.final_rms_px << "\n"
       << "max_rotation_error_deg " << runtime.max_rotation_error_deg << "\n"
       << "max_center_error_m " << runtime.max_center_error_m << "\n"
       << "error " << OneLine(runtime.error) << "\n";
  for (const StageRuntime& stage : runtime.stages) {
    text << "stage " << stage.seconds << " " << stage.cpu_seconds << " "
         << stage.num_iterations << " " << OneLine(stage.stage) << "\n";
  }
  return text.str();
}

bool ParseCalibrationRuntime(const std::string& text,
                             CalibrationRuntime* runtime, std::string* error) {
  Fields fields;
  CalibrationRuntime parsed;
  int success = 0;
  if (!fields.Parse(text, kCalibrationHeader, error) ||
      !fields.Integral("num_framesets", &parsed.num_framesets, error) ||
      !fields.Integral("num_cameras", &parsed.num_cameras, error) ||
      !fields.Integral("num_images", &parsed.num_images, error) ||
      !fields.Integral("num_correspondences", &parsed.num_correspondences,
                       error) ||
      !fields.Number("generation_seconds", &parsed.generation_seconds, error) ||
      !fields.Number("seconds", &parsed.seconds, error) ||
      !fields.Number("cpu_seconds", &parsed.cpu_seconds, error) ||
      !fields.Number("peak_memory_mb", &parsed.peak_memory_mb, error) ||
      !fields.Integral("success", &success, error) ||
      !fields.Number("final_rms_px", &parsed.final_rms_px, error) ||
      !fields.Number("max_rotation_error_deg", &parsed.max_rotation_error_deg,
                     error) ||
      !fields.Number("max_center_error_m", &parsed.max_center_error_m, error)) {
    return false;
  }
  parsed.success = success != 0;
  parsed.error = fields.Text("error");
  for (const std::string& line : fields.stages()) {
    std::istringstream stream(line);
    StageRuntime stage;
    if (!(stream >> stage.seconds >> stage.cpu_seconds >>
          stage.num_iterations)) {
      *error = "malformed stage line: " + line;
      return false;
    }
    std::getline(stream >> std::ws, stage.stage);
    parsed.stages.push_back(stage);
  }
  *runtime = parsed;
  return true;
}

std::string SerializeLocalizationRuntime(const LocalizationRuntime& runtime) {
  std::ostringstream text;
  text << std::setprecision(10) << kLocalizationHeader << "\n"
       << "mode " << OneLine(runtime.mode) << "\n"
       << "num_map_images " << runtime.num_map_images << "\n"
       << "num_map_points " << runtime.num_map_points << "\n"
       << "num_indexed_descriptors " << runtime.num_indexed_descriptors << "\n"
       << "features_per_rig_image " << runtime.features_per_rig_image << "\n"
       << "num_checks " << runtime.num_checks << "\n"
       << "num_images " << runtime.num_images << "\n"
       << "index_seconds " << runtime.index_seconds << "\n"
       << "index_cpu_seconds " << runtime.index_cpu_seconds << "\n"
       << "seconds " << runtime.seconds << "\n"
       << "cpu_seconds " << runtime.cpu_seconds << "\n"
       << "recall " << runtime.recall << "\n"
       << "precision " << runtime.precision << "\n"
       << "radial_pose_seconds_per_image "
       << runtime.radial_pose_seconds_per_image << "\n"
       << "num_poses_correct " << runtime.num_poses_correct << "\n"
       << "peak_memory_mb " << runtime.peak_memory_mb << "\n";
  return text.str();
}

bool ParseLocalizationRuntime(const std::string& text,
                              LocalizationRuntime* runtime,
                              std::string* error) {
  Fields fields;
  LocalizationRuntime parsed;
  if (!fields.Parse(text, kLocalizationHeader, error) ||
      !fields.Integral("num_map_images", &parsed.num_map_images, error) ||
      !fields.Integral("num_map_points", &parsed.num_map_points, error) ||
      !fields.Integral("num_indexed_descriptors",
                       &parsed.num_indexed_descriptors, error) ||
      !fields.Integral("features_per_rig_image", &parsed.features_per_rig_image,
                       error) ||
      !fields.Integral("num_checks", &parsed.num_checks, error) ||
      !fields.Integral("num_images", &parsed.num_images, error) ||
      !fields.Number("index_seconds", &parsed.index_seconds, error) ||
      !fields.Number("index_cpu_seconds", &parsed.index_cpu_seconds, error) ||
      !fields.Number("seconds", &parsed.seconds, error) ||
      !fields.Number("cpu_seconds", &parsed.cpu_seconds, error) ||
      !fields.Number("recall", &parsed.recall, error) ||
      !fields.Number("precision", &parsed.precision, error) ||
      !fields.Number("radial_pose_seconds_per_image",
                     &parsed.radial_pose_seconds_per_image, error) ||
      !fields.Integral("num_poses_correct", &parsed.num_poses_correct, error) ||
      !fields.Number("peak_memory_mb", &parsed.peak_memory_mb, error)) {
    return false;
  }
  parsed.mode = fields.Text("mode");
  *runtime = parsed;
  return true;
}

std::string CalibrationRuntimeCsv(const std::vector<CalibrationRuntime>& runs) {
  const std::vector<std::string> stages = StageNames(runs);
  std::ostringstream csv;
  csv << "framesets,cameras,images,correspondences,success";
  for (const std::string& stage : stages) {
    csv << ",\"" << stage << " wall s\",\"" << stage << " CPU s\",\"" << stage
        << " iterations\"";
  }
  csv << ",total wall s,total CPU s,peak memory MB,final RMS px,"
         "max rotation error deg,max center error m\n";
  for (const CalibrationRuntime& run : runs) {
    csv << run.num_framesets << "," << run.num_cameras << "," << run.num_images
        << "," << run.num_correspondences << "," << (run.success ? 1 : 0);
    for (const std::string& stage : stages) {
      const StageTotals totals = StageSeconds(run, stage);
      const bool ran = std::isfinite(totals.seconds);
      csv << "," << (ran ? FixedCell(totals.seconds, 3) : "") << ","
          << (ran ? FixedCell(totals.cpu_seconds, 3) : "") << ","
          << (ran ? std::to_string(totals.num_iterations) : "");
    }
    csv << "," << FixedCell(run.seconds, 3) << "," << FixedCell(run.cpu_seconds, 3)
        << "," << FixedCell(run.peak_memory_mb, 1) << ","
        << FixedCell(run.final_rms_px, 4) << ","
        << FixedCell(run.max_rotation_error_deg, 4) << ","
        << FixedCell(run.max_center_error_m, 5) << "\n";
  }
  return csv.str();
}

std::string LocalizationRuntimeCsv(
    const std::vector<LocalizationRuntime>& runs) {
  std::ostringstream csv;
  csv << "mode,map images,map points,indexed descriptors,features per rig "
         "image,checks,rig images,index wall s,index CPU s,localization wall s,"
         "localization CPU s,images per s,CPU s per image,recall,precision,"
         "radial pose s per image,poses correct,peak memory MB\n";
  for (const LocalizationRuntime& run : runs) {
    csv << run.mode << "," << run.num_map_images << "," << run.num_map_points
        << "," << run.num_indexed_descriptors << ","
        << run.features_per_rig_image << "," << run.num_checks << ","
        << run.num_images << "," << FixedCell(run.index_seconds, 3) << ","
        << FixedCell(run.index_cpu_seconds, 3) << "," << FixedCell(run.seconds, 3)
        << "," << FixedCell(run.cpu_seconds, 3) << ","
        << FixedCell(run.ImagesPerSecond(), 2) << ","
        << FixedCell(run.CpuSecondsPerImage(), 4) << "," << FixedCell(run.recall, 4)
        << "," << FixedCell(run.precision, 4) << ","
        << FixedCell(run.radial_pose_seconds_per_image, 5) << ","
        << run.num_poses_correct << "," << FixedCell(run.peak_memory_mb, 1) << "\n";
  }
  return csv.str();
}

double GrowthExponent(const std::vector<CalibrationRuntime>& runs,
                      int num_cameras) {
  const CalibrationRuntime* smallest = nullptr;
  const CalibrationRuntime* largest = nullptr;
  for (const CalibrationRuntime& run : runs) {
    if (run.num_cameras != num_cameras || !run.success ||
        run.cpu_seconds <= 0) {
      continue;
    }
    if (smallest == nullptr || run.num_framesets < smallest->num_framesets) {
      smallest = &run;
    }
    if (largest == nullptr || run.num_framesets > largest->num_framesets) {
      largest = &run;
    }
  }
  if (smallest == nullptr ||
      smallest->num_framesets == largest->num_framesets) {
    return std::nan("");
  }
  return std::log(largest->cpu_seconds / smallest->cpu_seconds) /
         std::log(static_cast<double>(largest->num_framesets) /
                  smallest->num_framesets);
}

std::string CalibrationRuntimeMarkdown(
    const std::vector<CalibrationRuntime>& runs) {
  const std::vector<std::string> stages = StageNames(runs);
  std::ostringstream md;
  md << "| framesets | cameras | images | correspondences |";
  for (const std::string& stage : stages) md << " " << stage << " |";
  md << " total wall s | total CPU s | peak memory MB | final RMS px | "
        "max rotation error deg | max center error mm |\n|---|---|---|---|";
  for (size_t s = 0; s < stages.size(); ++s) md << "---|";
  md << "---|---|---|---|---|---|\n";
  for (const CalibrationRuntime& run : runs) {
    md << "| " << run.num_framesets << " | " << run.num_cameras << " | "
       << run.num_images << " | " << run.num_correspondences << " |";
    for (const std::string& stage : stages) {
      const StageTotals totals = StageSeconds(run, stage);
      md << " " << FixedCell(totals.seconds, 2) << " ("
         << FixedCell(totals.cpu_seconds, 2) << ")"
         << (totals.num_iterations > 0
                 ? " [" + std::to_string(totals.num_iterations) + "]"
                 : "")
         << " |";
    }
    md << " " << FixedCell(run.seconds, 2) << " | " << FixedCell(run.cpu_seconds, 2)
       << " | " << FixedCell(run.peak_memory_mb, 0) << " | ";
    if (run.success) {
      md << FixedCell(run.final_rms_px, 3) << " | "
         << FixedCell(run.max_rotation_error_deg, 3) << " | "
         << FixedCell(1000 * run.max_center_error_m, 2) << " |\n";
    } else {
      md << "failed: " << run.error << " | - | - |\n";
    }
  }
  md << "\nStage cells: wall seconds (CPU seconds, user + system over all "
        "threads) [solver iterations].\n";
  for (const int num_cameras : CameraCounts(runs)) {
    const double exponent = GrowthExponent(runs, num_cameras);
    if (std::isfinite(exponent)) {
      md << "Growth with " << num_cameras << " cameras: CPU time ~ framesets^"
         << FixedCell(exponent, 2)
         << " between the smallest and the largest run (1 = linear).\n";
    }
  }
  return md.str();
}

std::string LocalizationRuntimeMarkdown(
    const std::vector<LocalizationRuntime>& runs) {
  std::ostringstream md;
  md << "| mode | map images | map points | features per rig image | "
        "checks | rig images | index built in s (CPU s) | images/s (wall) | "
        "CPU s per "
        "image | recall | precision | radial pose ms per image | poses "
        "within 0.5 deg | peak memory MB |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const LocalizationRuntime& run : runs) {
    md << "| " << run.mode << " | " << run.num_map_images << " | "
       << run.num_map_points << " | " << run.features_per_rig_image << " | "
       << (run.mode == "direct" ? std::to_string(run.num_checks) : "-") << " | "
       << run.num_images << " | " << FixedCell(run.index_seconds, 2) << " ("
       << FixedCell(run.index_cpu_seconds, 2) << ") | "
       << FixedCell(run.ImagesPerSecond(), 2) << " | "
       << FixedCell(run.CpuSecondsPerImage(), 3) << " | " << FixedCell(run.recall, 3)
       << " | " << FixedCell(run.precision, 3) << " | "
       << FixedCell(1000 * run.radial_pose_seconds_per_image, 2) << " | "
       << run.num_poses_correct << "/" << run.num_images << " | "
       << FixedCell(run.peak_memory_mb, 0) << " |\n";
  }
  return md.str();
}

namespace {

std::string StageCell(const StageTotals& totals) {
  if (!std::isfinite(totals.seconds)) return "-";
  return FixedCell(totals.seconds, 2) + " (" + FixedCell(totals.cpu_seconds, 2) + ")" +
         (totals.num_iterations > 0
              ? " [" + std::to_string(totals.num_iterations) + "]"
              : "");
}

// Relative change of an error, in percent.
std::string Change(double before, double after) {
  return before > 0 ? FixedCell(100 * (after - before) / before, 1) + " %" : "-";
}

}  // namespace

std::string CalibrationBeforeAfterMarkdown(
    const std::vector<CalibrationRuntime>& before,
    const std::vector<CalibrationRuntime>& after) {
  std::ostringstream md;
  for (size_t k = 0; k < before.size() && k < after.size(); ++k) {
    const CalibrationRuntime& b = before[k];
    const CalibrationRuntime& a = after[k];
    md << "### " << a.num_framesets << " framesets x " << a.num_cameras
       << " cameras (" << a.num_images << " images, " << a.num_correspondences
       << " correspondences)\n\n"
       << "| stage | before: wall s (CPU s) [iterations] | after | wall "
          "before/after | CPU before/after |\n|---|---|---|---|---|\n";
    for (const std::string& stage : StageNames({b, a})) {
      const StageTotals tb = StageSeconds(b, stage);
      const StageTotals ta = StageSeconds(a, stage);
      md << "| " << stage << " | " << StageCell(tb) << " | " << StageCell(ta)
         << " | " << RatioCell(tb.seconds, ta.seconds) << " | "
         << RatioCell(tb.cpu_seconds, ta.cpu_seconds) << " |\n";
    }
    md << "| **total** | " << FixedCell(b.seconds, 2) << " ("
       << FixedCell(b.cpu_seconds, 2) << ") | " << FixedCell(a.seconds, 2) << " ("
       << FixedCell(a.cpu_seconds, 2) << ") | " << RatioCell(b.seconds, a.seconds)
       << " | " << RatioCell(b.cpu_seconds, a.cpu_seconds) << " |\n"
       << "| peak memory MB | " << FixedCell(b.peak_memory_mb, 0) << " | "
       << FixedCell(a.peak_memory_mb, 0) << " | "
       << RatioCell(b.peak_memory_mb, a.peak_memory_mb) << " | |\n\n"
       << "| against the truth | before | after | change |\n"
       << "|---|---|---|---|\n"
       << "| success | " << (b.success ? "yes" : "no: " + b.error) << " | "
       << (a.success ? "yes" : "no: " + a.error) << " | |\n"
       << "| final RMS px | " << FixedCell(b.final_rms_px, 4) << " | "
       << FixedCell(a.final_rms_px, 4) << " | "
       << Change(b.final_rms_px, a.final_rms_px) << " |\n"
       << "| worst camera rotation error deg | "
       << FixedCell(b.max_rotation_error_deg, 4) << " | "
       << FixedCell(a.max_rotation_error_deg, 4) << " | "
       << Change(b.max_rotation_error_deg, a.max_rotation_error_deg) << " |\n"
       << "| worst camera center error mm | "
       << FixedCell(1000 * b.max_center_error_m, 3) << " | "
       << FixedCell(1000 * a.max_center_error_m, 3) << " | "
       << Change(b.max_center_error_m, a.max_center_error_m) << " |\n\n";
  }
  return md.str();
}

std::string CalibrationRuntimeSvg(const std::vector<CalibrationRuntime>& runs) {
  std::vector<PlotSeries> series;
  double y_max = 0;
  for (const int num_cameras : CameraCounts(runs)) {
    std::vector<const CalibrationRuntime*> selected;
    for (const CalibrationRuntime& run : runs) {
      if (run.num_cameras == num_cameras && run.success) {
        selected.push_back(&run);
      }
    }
    std::sort(selected.begin(), selected.end(),
              [](const CalibrationRuntime* a, const CalibrationRuntime* b) {
                return a->num_framesets < b->num_framesets;
              });
    PlotSeries wall, cpu;
    wall.label = std::to_string(num_cameras) + " cameras, wall";
    cpu.label = std::to_string(num_cameras) + " cameras, CPU";
    for (const CalibrationRuntime* run : selected) {
      wall.x.push_back(run->num_framesets);
      wall.y.push_back(run->seconds);
      cpu.x.push_back(run->num_framesets);
      cpu.y.push_back(run->cpu_seconds);
      y_max = std::max({y_max, run->seconds, run->cpu_seconds});
    }
    series.push_back(wall);
    series.push_back(cpu);
  }
  PlotOptions options;
  options.title = "Calibration core (CalibrateRig) time vs framesets";
  options.x_label = "framesets";
  options.y_label = "seconds";
  options.x_min = 0;
  options.y_min = 0;
  // Headroom above the highest point, which would sit on the frame.
  if (y_max > 0) options.y_max = 1.1 * y_max;
  return LinePlotSvg(options, series);
}

}  // namespace rig_calibrator
