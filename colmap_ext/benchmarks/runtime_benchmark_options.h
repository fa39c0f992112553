// The options of the runtime benchmark (`rig_calibrator_lab
// benchmark_runtime`), shared by the parent process, which runs every
// measurement in a child process, and the children, which get the parent's
// options plus the hidden ChildRequest.
#pragma once

#include <string>
#include <vector>

#include "colmap_ext/localization/point_descriptor_index.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {

// What one child process measures, and where it writes the result.
struct ChildRequest {
  std::string child;  // "calibration" / "localization"; empty in the parent
  std::string result_path;
  int framesets = 0;     // calibration
  int cameras = 0;       // calibration
  int rig_features = 0;  // localization
  int num_checks = 0;    // localization
  std::string mode;      // localization: "direct" / "retrieval"
  std::string work_dir;  // localization: where its database goes
};

struct RuntimeBenchmarkOptions {
  std::string output_path;
  // Comma-separated lists: one calibration run per frameset count x camera
  // count, one direct localization run per feature count x check count.
  std::string framesets = "10,50,100,500";
  std::string cameras = "5,10";
  std::string method = "1dr";
  // As `rig_calibrator calibrate` (--RigCalibrator.refine_points, on by
  // default): the final bundle adjustment also refines the map points.
  bool refine_points = true;
  // The synthetic data of the calibration runs: points_per_image, noise_px,
  // outlier_ratio, missing_image_ratio, map_point_noise (issue 14's
  // scenario: 300, 0.5 px, 30 % wrong matches, 10 % missing images, map
  // points with 5 mm of Gaussian error per coordinate: a triangulated map's
  // points are not exact, which is why the final BA refines them).
  SyntheticRigOptions data = [] {
    SyntheticRigOptions data;
    data.map_point_noise = 0.005;
    return data;
  }();
  int num_threads = -1;
  int seed = 0;
  // Another build of rig_calibrator (e.g. of an earlier commit): every
  // calibration run is made with it first, then with this one, on the same
  // data, and runtime.md gets a before/after table. It gets this run's
  // options but this one, so it must know them all.
  std::string baseline_executable;
  // Runs per calibration configuration (and build), alternating before and
  // after; each stage's time is the median over them (a shared machine's
  // speed drifts by 10-30 % between runs).
  int repeats = 1;
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

  ChildRequest request;
};

// A list option such as --framesets: "10,50,100" -> {10, 50, 100}; false
// for anything but positive integers (benchmarks' own, in
// runtime_benchmark_runner.cc).
bool ParseCountList(const std::string& text, std::vector<int>* values);

}  // namespace rig_calibrator
