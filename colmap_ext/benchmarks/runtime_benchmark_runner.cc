#include "colmap_ext/benchmarks/runtime_benchmark_runner.h"

#include <unistd.h>

#include <algorithm>
#include <boost/filesystem.hpp>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "colmap_ext/benchmarks/calibration_measurement.h"
#include "colmap_ext/benchmarks/child_process.h"
#include "colmap_ext/benchmarks/localization_measurement.h"
#include "colmap_ext/benchmarks/runtime_benchmark.h"
#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/io/error_output.h"
#include "src/calibration/pipeline.h"

namespace rig_calibrator {

// "10,50,100" -> {10, 50, 100}; false for anything but positive integers.
bool ParseCountList(const std::string& text, std::vector<int>* values) {
  values->clear();
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    try {
      size_t used = 0;
      const int value = std::stoi(item, &used);
      if (used != item.size() || value < 1) return false;
      values->push_back(value);
    } catch (const std::exception&) {
      return false;
    }
  }
  return !values->empty();
}

namespace {

namespace fs = std::filesystem;

bool WriteText(const std::string& path, const std::string& text) {
  std::string error;
  if (!WriteFileAtomically(path, text, &error)) {
    PrintError(error);
    return false;
  }
  return true;
}

std::string Seconds(double seconds) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(2) << seconds;
  return text.str();
}

// The parsed lists of the options, checked.
struct RunLists {
  std::vector<int> framesets, cameras, rig_features, num_checks;
};

bool MakeRunLists(const RuntimeBenchmarkOptions& options, RunLists* lists,
                  std::string* error) {
  if (!ParseCountList(options.framesets, &lists->framesets) ||
      !ParseCountList(options.cameras, &lists->cameras) ||
      !ParseCountList(options.rig_features, &lists->rig_features) ||
      !ParseCountList(options.num_checks, &lists->num_checks)) {
    *error =
        "--framesets, --cameras, --rig_features and --num_checks take "
        "comma-separated positive integers";
    return false;
  }
  for (const int num_cameras : lists->cameras) {
    SyntheticRigOptions check;
    check.ring_num_cameras = num_cameras;
    if (!check.Check(error)) {
      *error = "--cameras: " + *error;
      return false;
    }
  }
  CalibrationMethod method;
  if (!CalibrationMethodFromName(options.method, &method)) {
    *error = "unknown method " + options.method;
    return false;
  }
  return true;
}

// A fresh folder in the system's temporary folder ($TMPDIR) for the
// children's results and databases.
bool MakeWorkFolder(std::string* work_dir, std::string* error) {
  std::error_code code;
  *work_dir =
      (fs::temp_directory_path(code) /
       boost::filesystem::unique_path("rig_calibrator_runtime_%%%%-%%%%-%%%%")
           .string())
          .string();
  if (code || !fs::create_directory(*work_dir, code) || code) {
    *error = "cannot create a temporary folder " + *work_dir +
             (code ? ": " + code.message() : "");
    return false;
  }
  return true;
}

// Runs the child of `request` (with `executable`, by default this one) and
// returns its outcome.
ChildOutcome RunChild(const std::vector<std::string>& base_arguments,
                      const ChildRequest& request,
                      const std::string& executable = "/proc/self/exe") {
  std::vector<std::string> arguments = base_arguments;
  arguments.insert(arguments.end(), {"--child", request.child, "--child_result",
                                     request.result_path});
  if (request.child == "calibration") {
    arguments.insert(arguments.end(),
                     {"--child_framesets", std::to_string(request.framesets),
                      "--child_cameras", std::to_string(request.cameras)});
  } else {
    arguments.insert(arguments.end(),
                     {"--child_mode", request.mode, "--child_rig_features",
                      std::to_string(request.rig_features),
                      "--child_num_checks", std::to_string(request.num_checks),
                      "--child_work_dir", request.work_dir});
  }
  return RunChildProcess(arguments, request.result_path, executable);
}

// The parent's arguments without the parent-only options
// (--baseline_executable, --repeats) and their values, for the children: an
// older build, the baseline, does not know them.
std::vector<std::string> ChildArguments(
    const std::vector<std::string>& base_arguments) {
  std::vector<std::string> arguments = {base_arguments.front()};
  for (size_t i = 1; i < base_arguments.size(); ++i) {
    const std::string& argument = base_arguments[i];
    bool parent_only = false;
    for (const std::string option : {"--baseline_executable", "--repeats"}) {
      if (argument == option) {
        ++i;  // and its value
        parent_only = true;
      } else if (argument.rfind(option + "=", 0) == 0) {
        parent_only = true;
      }
    }
    if (!parent_only) arguments.push_back(argument);
  }
  return arguments;
}

std::vector<std::string> BaselineArguments(
    const std::vector<std::string>& base_arguments,
    const std::string& baseline_executable) {
  std::vector<std::string> arguments = ChildArguments(base_arguments);
  arguments.front() = baseline_executable;
  return arguments;
}

// One calibration child run of `executable`; a failure is a result.
CalibrationRuntime MeasureCalibrationRun(
    const std::vector<std::string>& arguments, const ChildRequest& request,
    const std::string& executable) {
  const ChildOutcome outcome = RunChild(arguments, request, executable);
  CalibrationRuntime runtime;
  std::string error = outcome.error;
  if (!outcome.ok ||
      !ParseCalibrationRuntime(outcome.result_text, &runtime, &error)) {
    runtime = CalibrationRuntime();
    runtime.num_framesets = request.framesets;
    runtime.num_cameras = request.cameras;
    runtime.error = error;
  }
  runtime.peak_memory_mb = outcome.peak_memory_mb;
  return runtime;
}

void PrintCalibrationRun(const CalibrationRuntime& runtime) {
  std::cout << "  " << std::setw(4) << runtime.num_framesets << " framesets x "
            << std::setw(2) << runtime.num_cameras << " cameras: "
            << (runtime.success ? "" : "FAILED (" + runtime.error + ") ")
            << Seconds(runtime.seconds) << " s wall, "
            << Seconds(runtime.cpu_seconds) << " s CPU, "
            << std::setprecision(0) << std::fixed << runtime.peak_memory_mb
            << " MB peak";
  for (const StageRuntime& stage : runtime.stages) {
    std::cout << "; " << stage.stage << " " << Seconds(stage.seconds);
  }
  std::cout << std::endl;
}

// Every frameset count x camera count; *all_ok is cleared by a failed run.
// With a baseline executable each configuration runs with it first, into
// *before_runs.
std::vector<CalibrationRuntime> RunCalibrations(
    const RuntimeBenchmarkOptions& options, const RunLists& lists,
    const std::vector<std::string>& base_arguments, const std::string& work_dir,
    std::vector<CalibrationRuntime>* before_runs, bool* all_ok) {
  std::cout << "Calibration core (" << options.method << ", "
            << options.data.points_per_image
            << " correspondences per image):" << std::endl;
  const bool with_baseline = !options.baseline_executable.empty();
  std::vector<CalibrationRuntime> runs;
  for (const int num_cameras : lists.cameras) {
    for (const int num_framesets : lists.framesets) {
      ChildRequest request;
      request.child = "calibration";
      request.framesets = num_framesets;
      request.cameras = num_cameras;
      request.result_path = work_dir + "/calibration_" +
                            std::to_string(num_framesets) + "x" +
                            std::to_string(num_cameras) + ".txt";
      std::vector<CalibrationRuntime> before_repeats, after_repeats;
      for (int repeat = 0; repeat < options.repeats; ++repeat) {
        if (options.repeats > 1) {
          std::cout << "  run " << repeat + 1 << " of " << options.repeats
                    << ":" << std::endl;
        }
        if (with_baseline) {
          std::cout << "  before (" << options.baseline_executable
                    << "):" << std::endl;
          before_repeats.push_back(MeasureCalibrationRun(
              BaselineArguments(base_arguments, options.baseline_executable),
              request, options.baseline_executable));
          PrintCalibrationRun(before_repeats.back());
          std::cout << "  after (this build):" << std::endl;
        }
        after_repeats.push_back(MeasureCalibrationRun(
            ChildArguments(base_arguments), request, "/proc/self/exe"));
        PrintCalibrationRun(after_repeats.back());
      }
      if (with_baseline) {
        before_runs->push_back(MedianCalibrationRuntime(before_repeats));
        *all_ok = *all_ok && before_runs->back().success;
      }
      runs.push_back(MedianCalibrationRuntime(after_repeats));
      *all_ok = *all_ok && runs.back().success;
      if (options.repeats > 1) {
        std::cout << "  median of " << options.repeats << " runs:" << std::endl;
        if (with_baseline) PrintCalibrationRun(before_runs->back());
        PrintCalibrationRun(runs.back());
      }
    }
  }
  return runs;
}

// Direct mode for every feature count and number of checks; retrieval
// matches images (slow): at the first ones only.
std::vector<ChildRequest> LocalizationRequests(const RunLists& lists,
                                               const std::string& work_dir) {
  std::vector<ChildRequest> requests;
  const auto add = [&](const std::string& mode, int features, int checks) {
    ChildRequest request;
    request.child = "localization";
    request.mode = mode;
    request.rig_features = features;
    request.num_checks = checks;
    request.work_dir = work_dir;
    request.result_path = work_dir + "/localization_" + mode + "_" +
                          std::to_string(features) + "_" +
                          std::to_string(checks) + ".txt";
    requests.push_back(request);
  };
  for (const int features : lists.rig_features) {
    for (const int checks : lists.num_checks) add("direct", features, checks);
    if (features == lists.rig_features.front()) {
      add("retrieval", features, lists.num_checks.front());
    }
  }
  return requests;
}

std::vector<LocalizationRuntime> RunLocalizations(
    const RuntimeBenchmarkOptions& options, const RunLists& lists,
    const std::vector<std::string>& base_arguments, const std::string& work_dir,
    bool* all_ok) {
  std::cout << "Localization against a " << options.map_images << "-image map ("
            << options.map_features << " features per map image):" << std::endl;
  std::vector<LocalizationRuntime> runs;
  for (const ChildRequest& request : LocalizationRequests(lists, work_dir)) {
    const ChildOutcome outcome = RunChild(base_arguments, request);
    LocalizationRuntime runtime;
    std::string error = outcome.error;
    if (!outcome.ok ||
        !ParseLocalizationRuntime(outcome.result_text, &runtime, &error)) {
      PrintError("localization (" + request.mode + ", " +
                 std::to_string(request.rig_features) + " features): " + error);
      *all_ok = false;
      continue;
    }
    runtime.peak_memory_mb = outcome.peak_memory_mb;
    std::cout << "  " << request.mode << ", " << request.rig_features
              << " features per rig image, " << request.num_checks
              << " checks: " << std::setprecision(2)
              << runtime.ImagesPerSecond() << " images/s, "
              << std::setprecision(3) << runtime.CpuSecondsPerImage()
              << " CPU s per image, index " << Seconds(runtime.index_seconds)
              << " s, recall " << runtime.recall << ", precision "
              << runtime.precision << std::endl;
    runs.push_back(runtime);
  }
  return runs;
}

std::string RuntimeMarkdown(
    const RuntimeBenchmarkOptions& options, const std::string& machine_before,
    const std::vector<CalibrationRuntime>& before_runs,
    const std::vector<CalibrationRuntime>& calibration_runs,
    const std::vector<LocalizationRuntime>& localization_runs) {
  std::ostringstream md;
  md << "# Runtime benchmark\n\n"
     << "Measured by `rig_calibrator_lab benchmark_runtime` on a machine with "
     << machine_before << " at the start and " << MachineDescription()
     << " at the end. CPU seconds (user + system over all threads) depend "
        "less on other work on the machine than wall seconds do.\n\n";
  if (!calibration_runs.empty()) {
    md << "## Calibration core\n\n"
       << "`CalibrateRig` (method " << options.method
       << (options.refine_points ? ", map points refined in the final BA"
                                 : ", map points fixed")
       << ") on synthetic rigs: ring5, or the same ring with 10 cameras; "
       << options.data.points_per_image << " correspondences per image, "
       << options.data.noise_px << " px noise, "
       << 100 * options.data.outlier_ratio << " % wrong matches, "
       << 100 * options.data.missing_image_ratio
       << " % missing images. Peak memory is that of the process that made "
          "the synthetic rig and calibrated it"
       << (options.repeats > 1
               ? " (the largest of " + std::to_string(options.repeats) +
                     " runs; the times are their medians)"
               : std::string())
       << ".\n\n"
       << CalibrationRuntimeMarkdown(calibration_runs) << "\n"
       << "![time vs framesets](runtime_calibration.svg)\n\n";
  }
  if (!before_runs.empty()) {
    md << "## Before / after\n\n"
       << "Each configuration ran with `" << options.baseline_executable
       << "` (before) and then with this build (after), on the same data, "
          "one after the other in this run"
       << (options.repeats > 1
               ? ", " + std::to_string(options.repeats) +
                     " times alternating; every time is the median over "
                     "those runs"
               : std::string())
       << ". Ratios > 1: the after build is faster.\n\n"
       << CalibrationBeforeAfterMarkdown(before_runs, calibration_runs);
  }
  if (!localization_runs.empty()) {
    md << "## Localization\n\n"
       << "`MapLocalizer::LocalizeImages` from features already in a COLMAP "
          "database, against a synthetic map of "
       << options.map_images << " images x " << options.map_features
       << " SIFT-like features (" << options.map_points_per_image
       << " with a 3D point, tracks of 4 images); half of each rig image's "
          "features re-observe map points. images/s is wall time with "
       << (options.num_threads > 0 ? std::to_string(options.num_threads)
                                   : std::string("all"))
       << " threads; index = building the localizer (once per map). The "
          "radial pose (one thread) is the pipeline's first stage on the "
          "found correspondences.\n\n"
       << LocalizationRuntimeMarkdown(localization_runs) << "\n";
  }
  return md.str();
}

// runtime.md and the CSV and SVG files of the runs there are.
bool WriteReport(const std::string& folder, const std::string& markdown,
                 const std::vector<CalibrationRuntime>& before_runs,
                 const std::vector<CalibrationRuntime>& calibration_runs,
                 const std::vector<LocalizationRuntime>& localization_runs) {
  bool written = WriteText(folder + "/runtime.md", markdown);
  if (!calibration_runs.empty()) {
    written = WriteText(folder + "/runtime_calibration.csv",
                        CalibrationRuntimeCsv(calibration_runs)) &&
              WriteText(folder + "/runtime_calibration.svg",
                        CalibrationRuntimeSvg(calibration_runs)) &&
              written;
  }
  if (!before_runs.empty()) {
    written = WriteText(folder + "/runtime_calibration_before.csv",
                        CalibrationRuntimeCsv(before_runs)) &&
              written;
  }
  if (!localization_runs.empty()) {
    written = WriteText(folder + "/runtime_localization.csv",
                        LocalizationRuntimeCsv(localization_runs)) &&
              written;
  }
  std::cout << "Wrote runtime.md"
            << (calibration_runs.empty()
                    ? ""
                    : ", runtime_calibration.csv, runtime_calibration.svg")
            << (before_runs.empty() ? "" : ", runtime_calibration_before.csv")
            << (localization_runs.empty() ? "" : ", runtime_localization.csv")
            << " in " << folder << std::endl;
  return written;
}

}  // namespace

int RunRuntimeBenchmarkParent(const RuntimeBenchmarkOptions& options,
                              const std::vector<std::string>& base_arguments) {
  RunLists lists;
  std::string error;
  if (!MakeRunLists(options, &lists, &error)) return PrintError(error);
  if (options.repeats < 1) {
    return PrintError("--repeats " + std::to_string(options.repeats) +
                      " must be at least 1 (runs per calibration "
                      "configuration)");
  }
  if (!options.baseline_executable.empty() &&
      access(options.baseline_executable.c_str(), X_OK) != 0) {
    return PrintError("--baseline_executable " + options.baseline_executable +
                      " is not an executable file (give the path of another "
                      "rig_calibrator build)");
  }
  std::error_code code;
  fs::create_directories(options.output_path, code);
  if (code) {
    return PrintError("cannot create " + options.output_path + ": " +
                      code.message());
  }
  std::string work_dir;
  if (!MakeWorkFolder(&work_dir, &error)) return PrintError(error);
  const std::string machine_before = MachineDescription();
  std::cout << "Runtime benchmark (" << machine_before << ")" << std::endl;

  bool all_ok = true;
  std::vector<CalibrationRuntime> before_runs, calibration_runs;
  if (options.calibration) {
    calibration_runs = RunCalibrations(options, lists, base_arguments, work_dir,
                                       &before_runs, &all_ok);
  }
  std::vector<LocalizationRuntime> localization_runs;
  if (options.localization) {
    localization_runs =
        RunLocalizations(options, lists, base_arguments, work_dir, &all_ok);
  }
  fs::remove_all(work_dir, code);
  const bool written =
      WriteReport(options.output_path,
                  RuntimeMarkdown(options, machine_before, before_runs,
                                  calibration_runs, localization_runs),
                  before_runs, calibration_runs, localization_runs);
  return written && all_ok ? EXIT_SUCCESS : EXIT_FAILURE;
}

int RunRuntimeBenchmarkChild(const RuntimeBenchmarkOptions& options) {
  const ChildRequest& request = options.request;
  std::string error;
  std::string result;
  if (request.child == "calibration") {
    CalibrationRuntime runtime;
    if (!MeasureCalibration(options, request.framesets, request.cameras,
                            &runtime, &error)) {
      return PrintError(error);
    }
    result = SerializeCalibrationRuntime(runtime);
  } else if (request.child == "localization") {
    LocalizationRuntime runtime;
    if (!MeasureLocalization(options, request, &runtime, &error)) {
      return PrintError(error);
    }
    result = SerializeLocalizationRuntime(runtime);
  } else {
    return PrintError("unknown --child " + request.child);
  }
  return WriteText(request.result_path, result) ? EXIT_SUCCESS : EXIT_FAILURE;
}

}  // namespace rig_calibrator
