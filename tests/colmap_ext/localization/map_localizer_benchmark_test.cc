// The map localizer's throughput (a disabled test: a measurement, not a
// check).
#include <gtest/gtest.h>

#include <chrono>
#include <ctime>
#include <iostream>

#include "colmap_ext/localization/map_localizer.h"
#include "tests/colmap_ext/localization/localization_scene.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace map_localizer_benchmark_test {

using testing::MakeScene;
using testing::SceneConfig;
using testing::SyntheticScene;

// Throughput on a map of 300 images x 2000 features (1200 with a 3D
// point), rig images of 2000 features (1000 of map points). Run with
// --gtest_also_run_disabled_tests; it prints a table and asserts nothing
// about time. CPU s/image (all threads) does not depend on the machine's
// load; images/s is wall time on 2 threads.
TEST(MapLocalizerBenchmark, DISABLED_Throughput) {
  SceneConfig config;
  config.num_map_images = 300;
  config.num_points = 300 * 1200 / 4;
  config.track_length = 4;
  config.map_distractors_per_image = 800;
  config.num_rig_images = 40;
  config.planted_per_rig_image = 1000;
  config.rig_distractors_per_image = 1000;
  testing::ScopedTempDir temp_dir;
  const std::string database_path = temp_dir.File("benchmark.db");
  SyntheticScene scene = MakeScene(config, database_path);
  DatabaseReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(database_path, &error)) << error;

  struct Variant {
    LocalizationMode mode;
    int max_descriptors_per_point;
    int num_checks;
    int num_images;
  };
  // Image matching costs far more per image: time a few images only.
  const Variant variants[] = {{LocalizationMode::kDirect, 4, 128, 40},
                              {LocalizationMode::kDirect, 2, 128, 40},
                              {LocalizationMode::kDirect, 1, 128, 40},
                              {LocalizationMode::kDirect, 4, 64, 40},
                              {LocalizationMode::kDirect, 4, 32, 40},
                              {LocalizationMode::kRetrieval, 4, 128, 4}};
  for (const Variant& variant : variants) {
    MapLocalizerOptions options;
    options.mode = variant.mode;
    options.max_descriptors_per_point = variant.max_descriptors_per_point;
    options.index.num_checks = variant.num_checks;
    options.num_threads = 2;
    options.progress_interval = 0;
    const auto start = std::chrono::steady_clock::now();
    std::unique_ptr<MapLocalizer> localizer =
        MapLocalizer::Create(options, scene.map, &reader, &error);
    ASSERT_NE(localizer, nullptr) << error;
    const double build_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
            .count();
    const std::vector<std::string> names(
        scene.rig_image_names.begin(),
        scene.rig_image_names.begin() + variant.num_images);
    std::vector<ImageLocalization> results;
    const auto localize_start = std::chrono::steady_clock::now();
    const std::clock_t cpu_start = std::clock();
    ASSERT_TRUE(localizer->LocalizeImages(names, &results, &error)) << error;
    const double cpu_seconds =
        static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                      localize_start)
            .count();
    int num_correct = 0;
    int num_returned = 0;
    int num_planted = 0;
    for (size_t r = 0; r < results.size(); ++r) {
      num_planted += scene.planted[r].size();
      for (size_t i = 0; i < results[r].correspondences.size(); ++i) {
        ++num_returned;
        const auto it = scene.planted[r].find(results[r].point2D_idxs[i]);
        num_correct += it != scene.planted[r].end() &&
                       static_cast<int64_t>(it->second) ==
                           results[r].correspondences[i].point3D_id;
      }
    }
    std::cout << LocalizationModeName(variant.mode) << " descriptors/point "
              << variant.max_descriptors_per_point << " checks "
              << variant.num_checks << ": "
              << localizer->NumIndexedDescriptors()
              << " indexed descriptors, ready in " << build_seconds << " s; "
              << names.size() << " images: " << cpu_seconds / names.size()
              << " CPU s/image, " << names.size() / seconds
              << " images/s (2 threads); recall "
              << static_cast<double>(num_correct) / num_planted
              << ", precision "
              << static_cast<double>(num_correct) / std::max(num_returned, 1)
              << std::endl;
  }
}

}  // namespace map_localizer_benchmark_test
}  // namespace rig_calibrator
