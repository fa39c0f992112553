// The paper's accuracy experiment (§5.2, Table 1) on synthetic rigs: every
// method calibrates the whole recording of every rig preset in every scene,
// and each camera's calibration is compared with the truth: rotation and
// camera-center error of cam_from_rig, reprojection error, focal length
// error and the projection difference of the intrinsics
// (src/evaluation/evaluation.h).
#pragma once

#include <string>
#include <vector>

#include "src/calibration/pipeline.h"
#include "src/evaluation/evaluation.h"
#include "src/experiments/benchmark_scenarios.h"
#include "src/experiments/paper_methods.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {

struct AccuracyOptions {
  std::vector<RigPreset> presets = AllRigPresets();
  std::vector<BenchmarkScene> scenes = BenchmarkScenes();
  std::vector<CalibrationMethod> methods = AccuracyTableMethods();
  int num_framesets = 60;
  // The recording of each preset and scene (preset, depths and
  // num_framesets are set per run; the rest, e.g. noise and wrong matches,
  // applies to all).
  SyntheticRigOptions recording;
  unsigned int seed = 0;
  // Runs are calibrated in parallel, each on one thread (-1: all cores).
  int num_threads = -1;
};

// One method on one preset in one scene.
struct AccuracyRun {
  RigPreset preset = RigPreset::kRing5;
  std::string scene;
  CalibrationMethod method = CalibrationMethod::kRadial1D;
  CalibrationMethod used_method = CalibrationMethod::kRadial1D;
  bool success = false;  // CalibrateRig returned true
  std::string error;     // why not
  std::vector<std::string> camera_names;
  std::vector<bool> camera_calibrated;
  // Per camera (empty if !success): against the truth, rig aligned on all
  // cameras' orientations without scale (the map is metric).
  CalibrationError errors;
  // Per camera: RMS reprojection error of the final calibration over the
  // camera's inlier correspondences, pixels.
  std::vector<double> reprojection_rms_px;
  double seconds = 0;
};

// Deterministic for a seed.
std::vector<AccuracyRun> RunAccuracyExperiment(const AccuracyOptions& options);

// The paper's Table 1 layout: per preset and scene, one line per measure
// (mean over cameras), one column per method.
std::string FormatAccuracyPaperTable(const std::vector<AccuracyRun>& runs);

// One row per preset x scene x method with the mean and max over cameras of
// rotation (deg), center (cm), reprojection (px), focal (%), principal point
// (px) and projection difference (px), and the run time.
std::string FormatAccuracyTable(const std::vector<AccuracyRun>& runs);

// The same as CSV (summary), and one CSV row per camera of every run.
std::string AccuracySummaryCsv(const std::vector<AccuracyRun>& runs);
std::string AccuracyPerCameraCsv(const std::vector<AccuracyRun>& runs);

}  // namespace rig_calibrator
