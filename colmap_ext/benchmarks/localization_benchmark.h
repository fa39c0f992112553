// The localization benchmark on a real COLMAP map (`rig_calibrator_lab
// benchmark_localization`, scripts/benchmark_localization.sh): MapLocalizer
// with given options on the rig images of a database (features extracted),
// timed (wall and CPU), with what it found: correspondences, the features
// searched in the index and matched along radial lines, and the 1D radial
// pose (EstimateRadialPose, principal point at the image center) of every
// image, whose inlier ratio tells how many correspondences are wrong.
#pragma once

#include <colmap/base/reconstruction.h>

#include <string>
#include <vector>

#include "colmap_ext/io/database_reader.h"
#include "colmap_ext/localization/map_localizer.h"

namespace rig_calibrator {

struct LocalizationBenchmarkResult {
  int num_threads = 0;
  int num_map_images = 0;
  long num_map_points = 0;
  long num_indexed_descriptors = 0;
  int num_images = 0;
  long num_features = 0;
  double index_seconds = 0, index_cpu_seconds = 0;  // MapLocalizer::Create
  double seconds = 0, cpu_seconds = 0;              // LocalizeImages
  long num_correspondences = 0;
  long num_index_queries = 0;
  long num_guided_queries = 0;
  // Images whose radial pose has >= min_num_inliers inliers, and the inliers
  // of all images / their correspondences.
  int num_posed_images = 0;
  long num_inliers = 0;
  double peak_memory_mb = 0;  // of the process so far (ru_maxrss)

  double ImagesPerSecond() const {
    return seconds > 0 ? num_images / seconds : 0;
  }
  // CPU seconds / (wall seconds x threads).
  double CpuUtilization() const {
    return seconds > 0 && num_threads > 0
               ? cpu_seconds / (seconds * num_threads)
               : 0;
  }
  double InlierRatio() const {
    return num_correspondences > 0 ? double(num_inliers) / num_correspondences
                                   : 0;
  }
};

// The database images that are not registered in `map`, by name.
std::vector<std::string> RigImageNames(const colmap::Reconstruction& map,
                                       const DatabaseReader& database);

// Builds the localizer, localizes `image_names` and estimates their radial
// poses (seeded with `seed`; images with fewer than `min_num_inliers`
// inliers count as not posed). False with *error if the localizer fails.
bool BenchmarkLocalization(const MapLocalizerOptions& options,
                           const colmap::Reconstruction& map,
                           const DatabaseReader& database,
                           const std::vector<std::string>& image_names,
                           int min_num_inliers, unsigned int seed,
                           LocalizationBenchmarkResult* result,
                           std::string* error);

// One CSV line (no newline) of `label`, `result` and `machine` (quoted), and
// its header.
std::string LocalizationBenchmarkCsvHeader();
std::string LocalizationBenchmarkCsvRow(
    const std::string& label, const LocalizationBenchmarkResult& result,
    const std::string& machine);

}  // namespace rig_calibrator
