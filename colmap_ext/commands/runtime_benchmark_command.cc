// `rig_calibrator benchmark_runtime`: how long the calibration takes and how
// much memory it needs (issue targets: the calibration core for 500
// framesets x 10 cameras x ~300 correspondences in under 60 s on 2 cores,
// growing about linearly with the framesets; localization of at least 5 rig
// images per second against a 300-image map).
//
//  * Calibration core: CalibrateRig (every stage the pipeline reports) on
//    synthetic rigs (ring5, or its 10-camera ring) for each frameset count x
//    camera count, in the scenario (0.5 px noise, 30 % wrong matches,
//    10 % missing images).
//  * Localization: MapLocalizer (features already in a COLMAP database) in
//    direct and retrieval mode against a synthetic 300-image map
//    (WriteSyntheticMapDatabase), then the 1D radial pose of each image.
//
// Every measurement runs in a child process (this executable again, with
// hidden --child options) so that its peak memory (wait4's ru_maxrss) is its
// own. Writes runtime.md, runtime_calibration.csv, runtime_localization.csv
// and runtime_calibration.svg into --output_path (created if needed; these
// files are replaced, others are left alone).
#include <colmap/util/random.h>
#include <colmap/util/timer.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <boost/filesystem.hpp>
#include <boost/program_options.hpp>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/commands/command_options.h"
#include "colmap_ext/commands/commands.h"
#include "colmap_ext/io/database_reader.h"
#include "colmap_ext/localization/map_localizer.h"
#include "colmap_ext/benchmarks/runtime_benchmark.h"
#include "colmap_ext/benchmarks/synthetic_map_database.h"
#include "src/evaluation/evaluation.h"
#include "src/calibration/pipeline.h"
#include "src/estimators/radial_pose_estimator.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {
namespace {

namespace fs = std::filesystem;

struct BenchmarkOptions {
  std::string output_path;
  std::string framesets = "10,50,100,500";
  std::string cameras = "5,10";
  std::string method = "1dr";
  // As `rig_calibrator calibrate` (--RigCalibrator.refine_points, on by
  // default): the final bundle adjustment also refines the map points.
  bool refine_points = true;
  int points_per_image = 300;
  double noise_px = 0.5;
  double outlier_ratio = 0.3;
  double missing_image_ratio = 0.1;
  int num_threads = -1;
  int seed = 0;
  bool calibration = true;
  bool localization = true;
  int map_images = 300;
  int map_features = 2000;
  int map_points_per_image = 1200;
  std::string rig_features = "2000,4096";
  // FLANN leaf checks of the direct index (PointDescriptorIndex::Options).
  std::string num_checks =
      std::to_string(PointDescriptorIndex::Options().num_checks);
  int rig_images = 40;
  int retrieval_images = 4;

  // Hidden: what a child process measures, and where it writes the result.
  std::string child;  // "calibration" / "localization"
  std::string child_result;
  int child_framesets = 0;
  int child_cameras = 0;
  int child_rig_features = 0;
  int child_num_checks = 0;
  std::string child_mode;
  std::string child_work_dir;
};

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

double ProcessCpuSeconds() {
  rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

bool WriteText(const std::string& path, const std::string& text) {
  std::string error;
  if (!WriteFileAtomically(path, text, &error)) {
    std::cerr << "ERROR: " << error << std::endl;
    return false;
  }
  return true;
}

std::string ReadText(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// --- child processes --------------------------------------------------------

int MeasureCalibration(const BenchmarkOptions& options) {
  CalibrationRuntime runtime;
  runtime.num_framesets = options.child_framesets;
  runtime.num_cameras = options.child_cameras;

  SyntheticRigOptions rig_options;
  rig_options.preset = RigPreset::kRing5;
  rig_options.ring_num_cameras = options.child_cameras;
  rig_options.num_framesets = options.child_framesets;
  rig_options.points_per_image = options.points_per_image;
  rig_options.noise_px = options.noise_px;
  rig_options.outlier_ratio = options.outlier_ratio;
  rig_options.missing_image_ratio = options.missing_image_ratio;
  rig_options.seed = static_cast<unsigned int>(options.seed);
  PipelineOptions pipeline_options;
  pipeline_options.num_threads = options.num_threads;
  pipeline_options.seed = static_cast<unsigned int>(options.seed);
  pipeline_options.print_progress = false;
  pipeline_options.final_bundle_adjustment.refine_points =
      options.refine_points;
  std::string error;
  if (!rig_options.Check(&error)) {
    std::cerr << "ERROR: " << error << std::endl;
    return EXIT_FAILURE;
  }
  if (!CalibrationMethodFromName(options.method, &pipeline_options.method)) {
    std::cerr << "ERROR: unknown method " << options.method << std::endl;
    return EXIT_FAILURE;
  }

  colmap::Timer timer;
  timer.Start();
  const SyntheticRig rig = GenerateSyntheticRig(rig_options);
  runtime.generation_seconds = timer.ElapsedSeconds();
  runtime.num_images = static_cast<int>(rig.dataset.images.size());
  for (const RigImage& image : rig.dataset.images) {
    runtime.num_correspondences += image.correspondences.size();
  }

  RigCalibration calibration;
  PipelineReport report;
  const double cpu_start = ProcessCpuSeconds();
  timer.Restart();
  runtime.success =
      CalibrateRig(pipeline_options, rig.dataset, &calibration, &report);
  runtime.seconds = timer.ElapsedSeconds();
  runtime.cpu_seconds = ProcessCpuSeconds() - cpu_start;
  runtime.error = report.error;
  runtime.final_rms_px = report.final_rms_px;
  for (const StageTiming& timing : report.timings) {
    runtime.stages.push_back(
        {timing.stage, timing.seconds, timing.cpu_seconds});
  }
  if (runtime.success) {
    const CalibrationError accuracy =
        CompareCalibrations(rig.truth.cameras, rig.truth.cam_from_rig,
                            calibration.cameras, calibration.cam_from_rig,
                            /*align_scale=*/false);
    runtime.max_rotation_error_deg = accuracy.MaxRotationDeg();
    runtime.max_center_error_m = accuracy.MaxCenterError();
  }
  return WriteText(options.child_result, SerializeCalibrationRuntime(runtime))
             ? EXIT_SUCCESS
             : EXIT_FAILURE;
}

int MeasureLocalization(const BenchmarkOptions& options) {
  LocalizationRuntime runtime;
  runtime.features_per_rig_image = options.child_rig_features;
  MapLocalizerOptions localizer_options;
  std::string error;
  if (!LocalizationModeFromName(options.child_mode, &localizer_options.mode)) {
    std::cerr << "ERROR: unknown localization mode " << options.child_mode
              << std::endl;
    return EXIT_FAILURE;
  }
  runtime.mode = options.child_mode;
  localizer_options.num_threads = options.num_threads;
  localizer_options.progress_interval = 0;
  if (options.child_num_checks > 0) {
    localizer_options.index.num_checks = options.child_num_checks;
  }
  runtime.num_checks = localizer_options.index.num_checks;

  SyntheticMapDatabaseOptions scene_options;
  scene_options.num_map_images = options.map_images;
  scene_options.features_per_map_image = options.map_features;
  scene_options.points_per_map_image = options.map_points_per_image;
  scene_options.num_rig_images =
      localizer_options.mode == LocalizationMode::kDirect
          ? options.rig_images
          : options.retrieval_images;
  scene_options.features_per_rig_image = options.child_rig_features;
  scene_options.map_points_per_rig_image = options.child_rig_features / 2;
  scene_options.seed = static_cast<unsigned int>(options.seed);
  const std::string database_path =
      (fs::path(options.child_work_dir) /
       ("map_" + options.child_mode + "_" +
        std::to_string(options.child_rig_features) + ".db"))
          .string();
  SyntheticMapDatabase scene;
  colmap::Timer timer;
  timer.Start();
  if (!WriteSyntheticMapDatabase(scene_options, database_path, &scene,
                                 &error)) {
    std::cerr << "ERROR: " << error << std::endl;
    return EXIT_FAILURE;
  }
  std::cout << "    synthetic database written in " << std::fixed
            << std::setprecision(1) << timer.ElapsedSeconds() << " s"
            << std::endl;
  DatabaseReader reader;
  if (!reader.Open(database_path, &error)) {
    std::cerr << "ERROR: " << error << std::endl;
    return EXIT_FAILURE;
  }

  double cpu_start = ProcessCpuSeconds();
  timer.Restart();
  std::unique_ptr<MapLocalizer> localizer =
      MapLocalizer::Create(localizer_options, scene.map, &reader, &error);
  if (localizer == nullptr) {
    std::cerr << "ERROR: " << error << std::endl;
    return EXIT_FAILURE;
  }
  runtime.index_seconds = timer.ElapsedSeconds();
  runtime.index_cpu_seconds = ProcessCpuSeconds() - cpu_start;
  runtime.num_map_images = static_cast<int>(localizer->NumMapImages());
  runtime.num_map_points = static_cast<long>(localizer->NumMapPoints());
  runtime.num_indexed_descriptors =
      static_cast<long>(localizer->NumIndexedDescriptors());

  std::vector<ImageLocalization> results;
  cpu_start = ProcessCpuSeconds();
  timer.Restart();
  if (!localizer->LocalizeImages(scene.rig_image_names, &results, &error)) {
    std::cerr << "ERROR: " << error << std::endl;
    return EXIT_FAILURE;
  }
  runtime.seconds = timer.ElapsedSeconds();
  runtime.cpu_seconds = ProcessCpuSeconds() - cpu_start;
  runtime.num_images = static_cast<int>(results.size());

  long num_correct = 0, num_returned = 0, num_planted = 0;
  for (size_t r = 0; r < results.size(); ++r) {
    num_planted += static_cast<long>(scene.rig_planted[r].size());
    for (size_t i = 0; i < results[r].correspondences.size(); ++i) {
      ++num_returned;
      const auto planted =
          scene.rig_planted[r].find(results[r].point2D_idxs[i]);
      num_correct += planted != scene.rig_planted[r].end() &&
                     static_cast<int64_t>(planted->second) ==
                         results[r].correspondences[i].point3D_id;
    }
  }
  runtime.recall = num_planted > 0 ? double(num_correct) / num_planted : 0;
  runtime.precision = num_returned > 0 ? double(num_correct) / num_returned : 0;

  // The 1D radial pose, as the pipeline's first stage computes it (principal
  // point at the image center).
  colmap::SetPRNGSeed(static_cast<unsigned int>(options.seed));
  const Eigen::Vector2d center(0.5 * scene_options.image_width,
                               0.5 * scene_options.image_height);
  timer.Restart();
  for (size_t r = 0; r < results.size(); ++r) {
    std::vector<Eigen::Vector2d> points2D;
    std::vector<Eigen::Vector3d> points3D;
    for (const Correspondence& correspondence : results[r].correspondences) {
      points2D.push_back(correspondence.point2D - center);
      points3D.push_back(correspondence.point3D);
    }
    RadialPoseEstimate estimate;
    if (EstimateRadialPose(RadialPoseEstimationOptions(), points2D, points3D,
                           &estimate) &&
        RotationDifferenceDeg(estimate.cam_from_world.rotation,
                              scene.rig_cam_from_world[r].rotation) < 0.5) {
      ++runtime.num_poses_correct;
    }
  }
  runtime.radial_pose_seconds_per_image =
      results.empty() ? 0 : timer.ElapsedSeconds() / results.size();
  localizer.reset();
  reader.Close();
  fs::remove(database_path);
  return WriteText(options.child_result, SerializeLocalizationRuntime(runtime))
             ? EXIT_SUCCESS
             : EXIT_FAILURE;
}

// --- the parent
// ---------------------------------------------------------------

struct ChildOutcome {
  bool ok = false;
  std::string result_text;
  double peak_memory_mb = 0;
  std::string error;
};

// Runs this executable with `arguments` + the child options, waits for it and
// reads its result file.
ChildOutcome RunChild(const std::vector<std::string>& arguments,
                      const std::string& result_path) {
  ChildOutcome outcome;
  std::vector<char*> child_argv;
  for (const std::string& argument : arguments) {
    child_argv.push_back(const_cast<char*>(argument.c_str()));
  }
  child_argv.push_back(nullptr);
  std::cout.flush();
  const pid_t pid = fork();
  if (pid < 0) {
    outcome.error = "fork failed";
    return outcome;
  }
  if (pid == 0) {
    execv("/proc/self/exe", child_argv.data());
    std::perror("execv /proc/self/exe");
    _exit(127);
  }
  int status = 0;
  rusage usage;
  if (wait4(pid, &status, 0, &usage) != pid) {
    outcome.error = "wait4 failed";
    return outcome;
  }
  // Linux reports ru_maxrss in kilobytes.
  outcome.peak_memory_mb = usage.ru_maxrss / 1024.0;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    outcome.error = WIFSIGNALED(status)
                        ? "the measurement was killed by signal " +
                              std::to_string(WTERMSIG(status))
                        : "the measurement exited with status " +
                              std::to_string(WEXITSTATUS(status));
    return outcome;
  }
  outcome.result_text = ReadText(result_path);
  outcome.ok = true;
  return outcome;
}

std::string Seconds(double seconds) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(2) << seconds;
  return text.str();
}

std::string MachineDescription() {
  std::ostringstream text;
  double load[3] = {0, 0, 0};
  getloadavg(load, 3);
  text << sysconf(_SC_NPROCESSORS_ONLN) << " cores online; load average "
       << std::fixed << std::setprecision(2) << load[0] << ", " << load[1]
       << ", " << load[2] << " (1, 5, 15 min)";
  return text.str();
}

int RunParent(const BenchmarkOptions& options,
              const std::vector<std::string>& base_arguments) {
  std::vector<int> framesets, cameras, rig_features, num_checks;
  if (!ParseCountList(options.framesets, &framesets) ||
      !ParseCountList(options.cameras, &cameras) ||
      !ParseCountList(options.rig_features, &rig_features) ||
      !ParseCountList(options.num_checks, &num_checks)) {
    std::cerr << "ERROR: --framesets, --cameras, --rig_features and "
                 "--num_checks take comma-separated positive integers"
              << std::endl;
    return EXIT_FAILURE;
  }
  for (const int num_cameras : cameras) {
    SyntheticRigOptions check;
    check.ring_num_cameras = num_cameras;
    std::string error;
    if (!check.Check(&error)) {
      std::cerr << "ERROR: --cameras: " << error << std::endl;
      return EXIT_FAILURE;
    }
  }
  CalibrationMethod method;
  if (!CalibrationMethodFromName(options.method, &method)) {
    std::cerr << "ERROR: unknown method " << options.method << std::endl;
    return EXIT_FAILURE;
  }
  std::error_code code;
  fs::create_directories(options.output_path, code);
  if (code) {
    std::cerr << "ERROR: cannot create " << options.output_path << ": "
              << code.message() << std::endl;
    return EXIT_FAILURE;
  }
  // The children's results and databases go to a fresh folder in the
  // system's temporary folder ($TMPDIR), removed at the end.
  const std::string work_dir =
      (fs::temp_directory_path(code) /
       boost::filesystem::unique_path("rig_calibrator_runtime_%%%%-%%%%-%%%%")
           .string())
          .string();
  if (code || !fs::create_directory(work_dir, code) || code) {
    std::cerr << "ERROR: cannot create a temporary folder " << work_dir
              << (code ? ": " + code.message() : "") << std::endl;
    return EXIT_FAILURE;
  }
  const std::string machine_before = MachineDescription();
  std::cout << "Runtime benchmark (" << machine_before << ")" << std::endl;

  bool all_ok = true;
  std::vector<CalibrationRuntime> calibration_runs;
  if (options.calibration) {
    std::cout << "Calibration core (" << options.method << ", "
              << options.points_per_image
              << " correspondences per image):" << std::endl;
    for (const int num_cameras : cameras) {
      for (const int num_framesets : framesets) {
        const std::string result_path = work_dir + "/calibration_" +
                                        std::to_string(num_framesets) + "x" +
                                        std::to_string(num_cameras) + ".txt";
        std::vector<std::string> arguments = base_arguments;
        arguments.insert(
            arguments.end(),
            {"--child", "calibration", "--child_framesets",
             std::to_string(num_framesets), "--child_cameras",
             std::to_string(num_cameras), "--child_result", result_path});
        const ChildOutcome outcome = RunChild(arguments, result_path);
        CalibrationRuntime runtime;
        std::string error = outcome.error;
        if (!outcome.ok ||
            !ParseCalibrationRuntime(outcome.result_text, &runtime, &error)) {
          runtime = CalibrationRuntime();
          runtime.num_framesets = num_framesets;
          runtime.num_cameras = num_cameras;
          runtime.error = error;
        }
        runtime.peak_memory_mb = outcome.peak_memory_mb;
        all_ok = all_ok && runtime.success;
        std::cout << "  " << std::setw(4) << num_framesets << " framesets x "
                  << std::setw(2) << num_cameras << " cameras: "
                  << (runtime.success ? "" : "FAILED (" + runtime.error + ") ")
                  << Seconds(runtime.seconds) << " s wall, "
                  << Seconds(runtime.cpu_seconds) << " s CPU, "
                  << std::setprecision(0) << std::fixed
                  << runtime.peak_memory_mb << " MB peak";
        for (const StageRuntime& stage : runtime.stages) {
          std::cout << "; " << stage.stage << " " << Seconds(stage.seconds);
        }
        std::cout << std::endl;
        calibration_runs.push_back(runtime);
      }
    }
  }

  std::vector<LocalizationRuntime> localization_runs;
  if (options.localization) {
    std::cout << "Localization against a " << options.map_images
              << "-image map (" << options.map_features
              << " features per map image):" << std::endl;
    // Direct mode for every feature count and number of checks; retrieval
    // matches images (slow): at the first ones only.
    struct Run {
      std::string mode;
      int features, checks;
    };
    std::vector<Run> runs;
    for (const int features : rig_features) {
      for (const int checks : num_checks) {
        runs.push_back({"direct", features, checks});
      }
      if (features == rig_features.front()) {
        runs.push_back({"retrieval", features, num_checks.front()});
      }
    }
    for (const Run& run : runs) {
      const std::string result_path = work_dir + "/localization_" + run.mode +
                                      "_" + std::to_string(run.features) + "_" +
                                      std::to_string(run.checks) + ".txt";
      std::vector<std::string> arguments = base_arguments;
      arguments.insert(
          arguments.end(),
          {"--child", "localization", "--child_mode", run.mode,
           "--child_rig_features", std::to_string(run.features),
           "--child_num_checks", std::to_string(run.checks), "--child_work_dir",
           work_dir, "--child_result", result_path});
      const ChildOutcome outcome = RunChild(arguments, result_path);
      LocalizationRuntime runtime;
      std::string error = outcome.error;
      if (!outcome.ok ||
          !ParseLocalizationRuntime(outcome.result_text, &runtime, &error)) {
        std::cerr << "ERROR: localization (" << run.mode << ", " << run.features
                  << " features): " << error << std::endl;
        all_ok = false;
        continue;
      }
      runtime.peak_memory_mb = outcome.peak_memory_mb;
      std::cout << "  " << run.mode << ", " << run.features
                << " features per rig image, " << run.checks
                << " checks: " << std::setprecision(2)
                << runtime.ImagesPerSecond() << " images/s, "
                << std::setprecision(3)
                << runtime.cpu_seconds / std::max(1, runtime.num_images)
                << " CPU s per image, index " << Seconds(runtime.index_seconds)
                << " s, recall " << runtime.recall << ", precision "
                << runtime.precision << std::endl;
      localization_runs.push_back(runtime);
    }
  }
  fs::remove_all(work_dir, code);

  std::ostringstream md;
  md << "# Runtime benchmark\n\n"
     << "Measured by `rig_calibrator benchmark_runtime` on a machine with "
     << machine_before << " at the start and " << MachineDescription()
     << " at the end. CPU seconds (user + system over all threads) depend "
        "less on other work on the machine than wall seconds do.\n\n";
  if (!calibration_runs.empty()) {
    md << "## Calibration core\n\n"
       << "`CalibrateRig` (method " << options.method
       << (options.refine_points ? ", map points refined in the final BA"
                                 : ", map points fixed")
       << ") on synthetic rigs: ring5, or the same ring with 10 cameras; "
       << options.points_per_image << " correspondences per image, "
       << options.noise_px << " px noise, " << 100 * options.outlier_ratio
       << " % wrong matches, " << 100 * options.missing_image_ratio
       << " % missing images. Peak memory is that of the process that made "
          "the synthetic rig and calibrated it.\n\n"
       << CalibrationRuntimeMarkdown(calibration_runs) << "\n"
       << "![time vs framesets](runtime_calibration.svg)\n\n";
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
  const std::string folder = options.output_path;
  bool written = WriteText(folder + "/runtime.md", md.str());
  if (!calibration_runs.empty()) {
    written = WriteText(folder + "/runtime_calibration.csv",
                        CalibrationRuntimeCsv(calibration_runs)) &&
              WriteText(folder + "/runtime_calibration.svg",
                        CalibrationRuntimeSvg(calibration_runs)) &&
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
            << (localization_runs.empty() ? "" : ", runtime_localization.csv")
            << " in " << folder << std::endl;
  return written && all_ok ? EXIT_SUCCESS : EXIT_FAILURE;
}

}  // namespace

int RunRuntimeBenchmark(int argc, char** argv) {
  BenchmarkOptions options;
  namespace po = boost::program_options;
  po::options_description description(
      "rig_calibrator benchmark_runtime options");
  description.add_options()("help,h", "show this help")(
      "output_path", po::value(&options.output_path)->required(),
      "results folder (created if needed): runtime.md, "
      "runtime_calibration.csv/.svg, runtime_localization.csv")(
      "framesets",
      po::value(&options.framesets)->default_value(options.framesets),
      "frameset counts of the calibration runs")(
      "cameras", po::value(&options.cameras)->default_value(options.cameras),
      "camera counts of the calibration runs (a ring of N cameras, ring5's "
      "layout)")("method",
                 po::value(&options.method)->default_value(options.method),
                 "calibration method")(
      "refine_points",
      po::value(&options.refine_points)->default_value(options.refine_points),
      "the final bundle adjustment also refines the map points (the "
      "calibrate command's default)")(
      "points_per_image",
      po::value(&options.points_per_image)
          ->default_value(options.points_per_image),
      "correspondences per image")(
      "noise_px", po::value(&options.noise_px)->default_value(options.noise_px),
      "pixel noise (standard deviation)")(
      "outlier_ratio",
      po::value(&options.outlier_ratio)->default_value(options.outlier_ratio),
      "share of wrong 2D-3D matches")(
      "missing_image_ratio",
      po::value(&options.missing_image_ratio)
          ->default_value(options.missing_image_ratio),
      "share of images dropped")(
      "num_threads",
      po::value(&options.num_threads)->default_value(options.num_threads),
      "threads (-1: all cores)")(
      "seed", po::value(&options.seed)->default_value(options.seed),
      "random seed")(
      "calibration",
      po::value(&options.calibration)->default_value(options.calibration),
      "measure the calibration core")(
      "localization",
      po::value(&options.localization)->default_value(options.localization),
      "measure the localization")(
      "map_images",
      po::value(&options.map_images)->default_value(options.map_images),
      "map images of the localization benchmark")(
      "map_features",
      po::value(&options.map_features)->default_value(options.map_features),
      "features per map image")(
      "map_points_per_image",
      po::value(&options.map_points_per_image)
          ->default_value(options.map_points_per_image),
      "features per map image that have a 3D point")(
      "rig_features",
      po::value(&options.rig_features)->default_value(options.rig_features),
      "features per rig image (comma-separated: one direct-mode run each; "
      "retrieval runs at the first)")(
      "rig_images",
      po::value(&options.rig_images)->default_value(options.rig_images),
      "rig images localized in direct mode")(
      "num_checks",
      po::value(&options.num_checks)->default_value(options.num_checks),
      "FLANN leaf checks of the direct index (comma-separated: one direct "
      "run each; retrieval runs at the first)")(
      "retrieval_images",
      po::value(&options.retrieval_images)
          ->default_value(options.retrieval_images),
      "rig images localized in retrieval mode (it matches images: slow)");
  po::options_description hidden("child process options");
  hidden.add_options()("child", po::value(&options.child))(
      "child_result", po::value(&options.child_result))(
      "child_framesets", po::value(&options.child_framesets))(
      "child_cameras", po::value(&options.child_cameras))(
      "child_rig_features", po::value(&options.child_rig_features))(
      "child_num_checks", po::value(&options.child_num_checks))(
      "child_mode", po::value(&options.child_mode))(
      "child_work_dir", po::value(&options.child_work_dir));
  po::options_description all;
  all.add(description).add(hidden);
  int exit_code = EXIT_SUCCESS;
  // The help shows the public options only.
  bool wants_help = false;
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    wants_help = wants_help || argument == "-h" || argument == "--help";
  }
  if (!ParseCommandLine(argc, argv, wants_help ? description : all,
                        "rig_calibrator benchmark_runtime: time and memory of "
                        "the calibration core and of the localization",
                        &exit_code)) {
    return exit_code;
  }
  if (options.child == "calibration") return MeasureCalibration(options);
  if (options.child == "localization") return MeasureLocalization(options);
  if (!options.child.empty()) {
    std::cerr << "ERROR: unknown --child " << options.child << std::endl;
    return EXIT_FAILURE;
  }
  // Children get the same options: program name, command, then argv[1..].
  std::vector<std::string> base_arguments = {argv[0], "benchmark_runtime"};
  for (int i = 1; i < argc; ++i) base_arguments.push_back(argv[i]);
  return RunParent(options, base_arguments);
}

}  // namespace rig_calibrator
