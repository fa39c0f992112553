#include "src/experiments/benchmark_scenarios.h"

namespace rig_calibrator {

std::vector<BenchmarkScene> BenchmarkScenes() {
  // name, depths (m), share on the ground plane, good center error (m).
  return {{"indoor", 1.0, 8.0, 0.2, 0.01}, {"outdoor", 4.0, 60.0, 0.3, 0.02}};
}

bool BenchmarkSceneFromName(const std::string& name, BenchmarkScene* scene) {
  for (const BenchmarkScene& candidate : BenchmarkScenes()) {
    if (candidate.name == name) {
      *scene = candidate;
      return true;
    }
  }
  return false;
}

void ApplyScene(const BenchmarkScene& scene, SyntheticRigOptions* options) {
  options->min_depth = scene.min_depth;
  options->max_depth = scene.max_depth;
  options->near_planar_ratio = scene.near_planar_ratio;
}

std::vector<BenchmarkDifficulty> BenchmarkDifficulties() {
  BenchmarkDifficulty easy;
  easy.name = "easy";
  easy.description =
      "300 correspondences per image over the whole image, 0.5 px noise, "
      "30 % wrong matches, 10 % missing images, every 2nd recording frameset";
  BenchmarkDifficulty hard;
  hard.name = "hard";
  hard.points_per_image = 60;
  hard.noise_px = 1.0;
  hard.outlier_ratio = 0.5;
  hard.missing_image_ratio = 0.35;
  hard.feature_window = 0.4;
  hard.frameset_stride = 1;
  hard.description =
      "60 correspondences per image in a random window of 40 % of the image "
      "side, 1 px noise, 50 % wrong matches, 35 % missing images, "
      "consecutive recording framesets";
  return {easy, hard};
}

bool BenchmarkDifficultyFromName(const std::string& name,
                                 BenchmarkDifficulty* difficulty) {
  for (const BenchmarkDifficulty& candidate : BenchmarkDifficulties()) {
    if (candidate.name == name) {
      *difficulty = candidate;
      return true;
    }
  }
  return false;
}

void ApplyDifficulty(const BenchmarkDifficulty& difficulty,
                     ShortSequenceOptions* options) {
  options->recording.points_per_image = difficulty.points_per_image;
  options->recording.noise_px = difficulty.noise_px;
  options->recording.outlier_ratio = difficulty.outlier_ratio;
  options->recording.missing_image_ratio = difficulty.missing_image_ratio;
  options->recording.feature_window = difficulty.feature_window;
  options->frameset_stride = difficulty.frameset_stride;
}

}  // namespace rig_calibrator
