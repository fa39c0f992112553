#include "src/experiments/accuracy_experiment.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <limits>
#include <sstream>

#include "src/experiments/experiment_calibration.h"

namespace rig_calibrator {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Recording {
  RigPreset preset = RigPreset::kRing5;
  std::string scene;
  SyntheticRig rig;
};

AccuracyRun CalibrateRecording(const Recording& recording,
                               CalibrationMethod method, unsigned int seed) {
  AccuracyRun run;
  run.preset = recording.preset;
  run.scene = recording.scene;
  run.method = method;
  run.camera_names = recording.rig.truth.camera_names;
  const SyntheticRig& rig = recording.rig;
  const ExperimentCalibration result = CalibrateSyntheticRig(rig, method, seed);
  const RigCalibration& calibration = result.calibration;
  run.success = result.success;
  run.seconds = result.report.total_seconds;
  run.used_method = result.report.used_method;
  if (!run.success) {
    run.error = result.report.error;
    return run;
  }
  run.camera_calibrated = calibration.camera_calibrated;
  run.errors =
      CompareCalibrations(rig.truth.cameras, rig.truth.cam_from_rig,
                          calibration.cameras, calibration.cam_from_rig,
                          /*align_scale=*/false);
  if (!run.errors.ok()) {
    run.success = false;
    run.error = run.errors.error;
    return run;
  }
  // RMS over the camera's inliers: sqrt(sum_i n_i rms_i^2 / sum_i n_i).
  const size_t num_cameras = rig.dataset.cameras.size();
  std::vector<double> sum_squares(num_cameras, 0), count(num_cameras, 0);
  for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
    const ImageResult& image = calibration.images[i];
    if (!image.used || image.num_inliers == 0) continue;
    const int c = rig.dataset.images[i].camera_index;
    sum_squares[c] += image.num_inliers * image.rms_px * image.rms_px;
    count[c] += image.num_inliers;
  }
  for (size_t c = 0; c < num_cameras; ++c) {
    run.reprojection_rms_px.push_back(
        count[c] > 0 ? std::sqrt(sum_squares[c] / count[c]) : kNaN);
  }
  return run;
}

// Per camera values of one measure of a run; NaN for uncalibrated cameras.
using Measure = std::function<double(const AccuracyRun&, size_t camera)>;

struct MeasureColumn {
  std::string name;      // with unit, for the tables
  std::string csv_name;  // with unit, for the CSV columns
  Measure value;
  int precision;
};

// A field of the camera's CameraError, times `factor` (unit change).
Measure CameraErrorField(double CameraError::*field, double factor) {
  return [field, factor](const AccuracyRun& run, size_t c) {
    return factor * (run.errors.cameras[c].*field);
  };
}

const std::vector<MeasureColumn>& Measures() {
  static const std::vector<MeasureColumn> measures = {
      {"rotation (deg)", "rotation_deg",
       CameraErrorField(&CameraError::rotation_deg, 1), 3},
      {"translation (cm)", "translation_cm",
       CameraErrorField(&CameraError::center_error, 100), 3},
      {"reprojection (px)", "reprojection_px",
       [](const AccuracyRun& run, size_t c) {
         return run.reprojection_rms_px[c];
       },
       3},
      {"focal (%)", "focal_percent",
       CameraErrorField(&CameraError::focal_error_percent, 1), 3},
      {"principal point (px)", "principal_point_px",
       CameraErrorField(&CameraError::principal_point_error_px, 1), 2},
      {"projection diff. (px)", "projection_diff_px",
       CameraErrorField(&CameraError::mean_projection_diff_px, 1), 3},
  };
  return measures;
}

bool CameraCounts(const AccuracyRun& run, size_t c) {
  return run.success && c < run.camera_calibrated.size() &&
         run.camera_calibrated[c] && c < run.errors.cameras.size();
}

// Mean and max over the calibrated cameras (NaN if none).
void MeanMax(const AccuracyRun& run, const Measure& measure, double* mean,
             double* max) {
  double sum = 0;
  int count = 0;
  *max = kNaN;
  for (size_t c = 0; c < run.camera_names.size(); ++c) {
    if (!CameraCounts(run, c)) continue;
    const double value = measure(run, c);
    if (!std::isfinite(value)) continue;
    sum += value;
    ++count;
    *max = count == 1 ? value : std::max(*max, value);
  }
  *mean = count > 0 ? sum / count : kNaN;
}

std::string MethodLabel(const AccuracyRun& run) {
  std::string label = CalibrationMethodName(run.method);
  if (run.used_method != run.method) {
    label += " (as " + CalibrationMethodName(run.used_method) + ")";
  }
  return label;
}

std::string Fixed(double value, int precision) {
  if (!std::isfinite(value)) return "-";
  std::ostringstream text;
  text << std::fixed << std::setprecision(precision) << value;
  return text.str();
}

int NumCalibrated(const AccuracyRun& run) {
  return static_cast<int>(std::count(run.camera_calibrated.begin(),
                                     run.camera_calibrated.end(), true));
}

}  // namespace

std::vector<AccuracyRun> RunAccuracyExperiment(const AccuracyOptions& options) {
  std::vector<Recording> recordings;
  for (const RigPreset preset : options.presets) {
    for (const BenchmarkScene& scene : options.scenes) {
      SyntheticRigOptions rig_options = options.recording;
      rig_options.preset = preset;
      rig_options.num_framesets = options.num_framesets;
      rig_options.seed = options.seed;
      ApplyScene(scene, &rig_options);
      recordings.push_back({preset, scene.name, SyntheticRig()});
      recordings.back().rig = GenerateSyntheticRig(rig_options);
    }
  }
  const int num_methods = static_cast<int>(options.methods.size());
  const int num_runs = static_cast<int>(recordings.size()) * num_methods;
  std::vector<AccuracyRun> runs(num_runs);
  const int num_threads =
      options.num_threads > 0 ? options.num_threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic) num_threads(num_threads)
  for (int r = 0; r < num_runs; ++r) {
    runs[r] =
        CalibrateRecording(recordings[r / num_methods],
                           options.methods[r % num_methods], options.seed);
  }
  return runs;
}

std::string FormatAccuracyPaperTable(const std::vector<AccuracyRun>& runs) {
  // Columns: the methods in order of first appearance.
  std::vector<CalibrationMethod> methods;
  std::vector<std::pair<RigPreset, std::string>> cells;
  for (const AccuracyRun& run : runs) {
    if (std::find(methods.begin(), methods.end(), run.method) ==
        methods.end()) {
      methods.push_back(run.method);
    }
    const std::pair<RigPreset, std::string> cell(run.preset, run.scene);
    if (std::find(cells.begin(), cells.end(), cell) == cells.end()) {
      cells.push_back(cell);
    }
  }
  bool any_fallback = false;
  std::ostringstream table;
  table << "| rig / scene | mean over cameras |";
  for (const CalibrationMethod method : methods) {
    table << " " << CalibrationMethodName(method) << " |";
  }
  table << "\n|---|---|";
  for (size_t m = 0; m < methods.size(); ++m) table << "---|";
  table << "\n";
  for (const auto& [preset, scene] : cells) {
    for (size_t k = 0; k < Measures().size(); ++k) {
      const MeasureColumn& measure = Measures()[k];
      table << "| "
            << (k == 0 ? "**" + RigPresetName(preset) + " / " + scene + "**"
                       : "")
            << " | " << measure.name << " |";
      for (const CalibrationMethod method : methods) {
        // C++17 lambdas cannot capture structured bindings (clang refuses;
        // the fuzz build compiles this file with clang): init-captures.
        const auto run = std::find_if(
            runs.begin(), runs.end(),
            [&, &preset = preset, &scene = scene](const AccuracyRun& candidate) {
              return candidate.preset == preset && candidate.scene == scene &&
                     candidate.method == method;
            });
        double mean = kNaN, max = kNaN;
        if (run != runs.end()) MeanMax(*run, measure.value, &mean, &max);
        const bool fell_back = run != runs.end() && run->used_method != method;
        any_fallback = any_fallback || fell_back;
        table << " " << Fixed(mean, measure.precision)
              << (fell_back && k == 0 ? "¹" : "") << " |";
      }
      table << "\n";
    }
  }
  if (any_fallback) {
    table << "\n¹ 1dr fell back to rd_ra: the cameras' principal axes are "
             "parallel (paper, Limitations).\n";
  }
  return table.str();
}

std::string FormatAccuracyTable(const std::vector<AccuracyRun>& runs) {
  std::ostringstream table;
  table << "| rig | scene | method | cameras |";
  for (const MeasureColumn& measure : Measures()) {
    table << " " << measure.name << " mean / max |";
  }
  table << " seconds |\n|---|---|---|---|";
  for (size_t k = 0; k < Measures().size(); ++k) table << "---|";
  table << "---|\n";
  for (const AccuracyRun& run : runs) {
    table << "| " << RigPresetName(run.preset) << " | " << run.scene << " | "
          << MethodLabel(run) << " | " << NumCalibrated(run) << "/"
          << run.camera_names.size() << " |";
    for (const MeasureColumn& measure : Measures()) {
      double mean = kNaN, max = kNaN;
      MeanMax(run, measure.value, &mean, &max);
      table << " " << Fixed(mean, measure.precision) << " / "
            << Fixed(max, measure.precision) << " |";
    }
    table << " " << Fixed(run.seconds, 1) << " |\n";
  }
  return table.str();
}

std::string AccuracySummaryCsv(const std::vector<AccuracyRun>& runs) {
  std::ostringstream csv;
  csv << "rig,scene,method,used_method,success,cameras_calibrated,cameras";
  for (const MeasureColumn& measure : Measures()) {
    csv << "," << measure.csv_name << "_mean," << measure.csv_name << "_max";
  }
  csv << ",seconds\n";
  csv << std::setprecision(6);
  for (const AccuracyRun& run : runs) {
    csv << RigPresetName(run.preset) << "," << run.scene << ","
        << CalibrationMethodName(run.method) << ","
        << CalibrationMethodName(run.used_method) << ","
        << (run.success ? 1 : 0) << "," << NumCalibrated(run) << ","
        << run.camera_names.size();
    for (const MeasureColumn& measure : Measures()) {
      double mean = kNaN, max = kNaN;
      MeanMax(run, measure.value, &mean, &max);
      csv << "," << mean << "," << max;
    }
    csv << "," << run.seconds << "\n";
  }
  return csv.str();
}

std::string AccuracyPerCameraCsv(const std::vector<AccuracyRun>& runs) {
  std::ostringstream csv;
  csv << "rig,scene,method,used_method,camera,calibrated,rotation_deg,"
         "translation_cm,reprojection_px,focal_percent,principal_point_px,"
         "projection_diff_px_mean,projection_diff_px_max\n";
  csv << std::setprecision(6);
  for (const AccuracyRun& run : runs) {
    for (size_t c = 0; c < run.camera_names.size(); ++c) {
      csv << RigPresetName(run.preset) << "," << run.scene << ","
          << CalibrationMethodName(run.method) << ","
          << CalibrationMethodName(run.used_method) << ","
          << run.camera_names[c] << "," << (CameraCounts(run, c) ? 1 : 0);
      if (!CameraCounts(run, c)) {
        csv << ",,,,,,,\n";
        continue;
      }
      const CameraError& error = run.errors.cameras[c];
      csv << "," << error.rotation_deg << "," << 100 * error.center_error << ","
          << run.reprojection_rms_px[c] << "," << error.focal_error_percent
          << "," << error.principal_point_error_px << ","
          << error.mean_projection_diff_px << ","
          << error.max_projection_diff_px << "\n";
    }
  }
  return csv.str();
}

}  // namespace rig_calibrator
