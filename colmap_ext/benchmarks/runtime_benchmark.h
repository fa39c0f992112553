// Results of the runtime benchmark (`rig_calibrator_lab benchmark_runtime`) and
// their reports: Markdown tables, CSV files and an SVG plot of the
// calibration time against the number of framesets.
//
// Every measurement runs in its own child process, so its peak memory is the
// child's own (getrusage/wait4 ru_maxrss); measurements travel from the child
// to the parent as a small text file (Serialize/Parse below). Times are given
// both as wall time and as CPU time (user + system, all threads): wall time
// grows when other work shares the machine, CPU time hardly does.
#pragma once

#include <cmath>
#include <string>
#include <vector>

namespace rig_calibrator {

struct StageRuntime {
  std::string stage;
  double seconds = 0;      // wall
  double cpu_seconds = 0;  // user + system, all threads
  int num_iterations = 0;  // solver iterations (bundle adjustments)
};

// One run of the calibration core (CalibrateRig) on a synthetic rig.
struct CalibrationRuntime {
  int num_framesets = 0;
  int num_cameras = 0;
  int num_images = 0;
  long num_correspondences = 0;
  double generation_seconds = 0;  // making the synthetic rig (not counted)
  std::vector<StageRuntime> stages;
  double seconds = 0, cpu_seconds = 0;  // CalibrateRig as a whole
  double peak_memory_mb = 0;            // the child process's peak RSS
  bool success = false;
  std::string error;  // why the calibration failed
  double final_rms_px = 0;
  // Sanity check of the result against the truth (worst camera).
  double max_rotation_error_deg = 0, max_center_error_m = 0;
};

// Localization of rig images from features in a COLMAP database against a
// synthetic map, in one mode.
struct LocalizationRuntime {
  std::string mode;  // "direct" / "retrieval"
  int num_map_images = 0;
  long num_map_points = 0;
  long num_indexed_descriptors = 0;
  int features_per_rig_image = 0;
  int num_checks = 0;        // FLANN leaf checks of the direct index
  int num_images = 0;        // rig images localized
  double index_seconds = 0;  // MapLocalizer::Create, wall
  double index_cpu_seconds = 0;
  double seconds = 0, cpu_seconds = 0;  // LocalizeImages, all images
  // Correspondences agreeing with the planted ones / planted, and / returned.
  double recall = 0, precision = 0;
  // The 1D radial pose (EstimateRadialPose) of every localized image, one
  // thread: seconds per image, and images whose rotation is within 0.5
  // degrees of the truth.
  double radial_pose_seconds_per_image = 0;
  int num_poses_correct = 0;
  double peak_memory_mb = 0;

  double ImagesPerSecond() const {
    return seconds > 0 ? num_images / seconds : 0;
  }
  // All threads' CPU seconds of LocalizeImages per image; NaN without images.
  double CpuSecondsPerImage() const {
    return num_images > 0 ? cpu_seconds / num_images : std::nan("");
  }
};

// Line-based text exchanged between the benchmark's processes; Parse* returns
// false with *error for text that is not a serialized result.
std::string SerializeCalibrationRuntime(const CalibrationRuntime& runtime);
bool ParseCalibrationRuntime(const std::string& text,
                             CalibrationRuntime* runtime, std::string* error);
std::string SerializeLocalizationRuntime(const LocalizationRuntime& runtime);
bool ParseLocalizationRuntime(const std::string& text,
                              LocalizationRuntime* runtime, std::string* error);

// One run standing for repeated runs of the same configuration and build:
// every stage's wall and CPU seconds and the totals are the medians over the
// runs (the mean of the middle two for an even count), the peak memory the
// largest; the rest (counts, iterations, accuracy: deterministic) is the
// first run's. A failed run stands for all.
CalibrationRuntime MedianCalibrationRuntime(
    const std::vector<CalibrationRuntime>& runs);

// CSV with a header row: one row per run; calibration runs have a wall and a
// CPU column per stage (stages in order of first appearance over all runs;
// empty cells for stages a run did not have).
std::string CalibrationRuntimeCsv(const std::vector<CalibrationRuntime>& runs);
std::string LocalizationRuntimeCsv(
    const std::vector<LocalizationRuntime>& runs);

// Exponent b of time ~ framesets^b between the smallest and the largest
// frameset count measured with `num_cameras` cameras (successful runs, CPU
// time); NaN with fewer than two such counts. 1 is linear growth.
double GrowthExponent(const std::vector<CalibrationRuntime>& runs,
                      int num_cameras);

// Markdown sections (tables and notes) for the README.
std::string CalibrationRuntimeMarkdown(
    const std::vector<CalibrationRuntime>& runs);
std::string LocalizationRuntimeMarkdown(
    const std::vector<LocalizationRuntime>& runs);

// Per pair of runs of the same configuration (before[k], after[k]): a table
// with a row per stage (wall s (CPU s) [iterations] of each, and the ratio
// before / after of wall and of CPU), the totals, the peak memory and the
// errors against the truth, with their relative change.
std::string CalibrationBeforeAfterMarkdown(
    const std::vector<CalibrationRuntime>& before,
    const std::vector<CalibrationRuntime>& after);

// Line plot: total wall and CPU seconds of CalibrateRig against framesets,
// one pair of series per camera count (linear axes, so linear growth shows
// as a straight line).
std::string CalibrationRuntimeSvg(const std::vector<CalibrationRuntime>& runs);

}  // namespace rig_calibrator
