// The synthetic scenarios of the benchmark (paper §5): the scenes the rig is
// recorded in (the paper's indoor and outdoor datasets) and how hard the
// short-sequence robustness experiment is (§5.3, Table 3).
#pragma once

#include <string>
#include <vector>

#include "src/experiments/short_sequence_experiment.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {

struct BenchmarkScene {
  std::string name;
  // Distances of the map points from the observing camera (map units =
  // metres) and the share of them on the ground plane.
  double min_depth = 2.0, max_depth = 10.0;
  double near_planar_ratio = 0.0;
  // A calibration is "good" below this camera-center error (paper §5.3:
  // 1 cm indoors, 2 cm outdoors) and below 1 degree of rotation error.
  double good_center_error = 0.01;
};

// "indoor": a room, points 1-8 m away, 20 % on the floor, good < 1 cm.
// "outdoor": a street, points 4-60 m away, 30 % on the road, good < 2 cm.
std::vector<BenchmarkScene> BenchmarkScenes();

bool BenchmarkSceneFromName(const std::string& name, BenchmarkScene* scene);
void ApplyScene(const BenchmarkScene& scene, SyntheticRigOptions* options);

// How much and how good the data of a short sequence is.
struct BenchmarkDifficulty {
  std::string name;
  std::string description;  // one line for the report
  int points_per_image = 300;
  double noise_px = 0.5;
  double outlier_ratio = 0.3;
  double missing_image_ratio = 0.1;
  double feature_window = 1.0;  // see SyntheticRigOptions
  int frameset_stride = 2;      // recording framesets between sequence ones
};

// "easy": the generator's defaults (300 correspondences over the whole image,
// 0.5 px noise, 30 % wrong matches, 10 % missing images, framesets 0.8 m
// apart). "hard": what makes real short sequences fail (paper §5.3): few
// correspondences per image, clustered in a part of the image, more noise
// and wrong matches, more missing images, and framesets closer together
// (less motion).
std::vector<BenchmarkDifficulty> BenchmarkDifficulties();
bool BenchmarkDifficultyFromName(const std::string& name,
                                 BenchmarkDifficulty* difficulty);
void ApplyDifficulty(const BenchmarkDifficulty& difficulty,
                     ShortSequenceOptions* options);

}  // namespace rig_calibrator
