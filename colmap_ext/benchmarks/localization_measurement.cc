#include "colmap_ext/benchmarks/localization_measurement.h"

#include <colmap/util/random.h>
#include <colmap/util/timer.h>

#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <vector>

#include "colmap_ext/benchmarks/child_process.h"
#include "colmap_ext/benchmarks/synthetic_map_database.h"
#include "colmap_ext/io/database_reader.h"
#include "colmap_ext/localization/map_localizer.h"
#include "src/estimators/radial_pose_estimator.h"

namespace rig_calibrator {
namespace {

// Recall (correct / planted) and precision (correct / returned) of the
// correspondences against the planted ones.
void ScoreCorrespondences(const SyntheticMapDatabase& scene,
                          const std::vector<ImageLocalization>& results,
                          LocalizationRuntime* runtime) {
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
  runtime->recall = num_planted > 0 ? double(num_correct) / num_planted : 0;
  runtime->precision =
      num_returned > 0 ? double(num_correct) / num_returned : 0;
}

// The 1D radial pose, as the pipeline's first stage computes it (principal
// point at the image center): seconds per image and the poses within 0.5
// degrees of the truth.
void TimeRadialPoses(const SyntheticMapDatabaseOptions& scene_options,
                     const SyntheticMapDatabase& scene,
                     const std::vector<ImageLocalization>& results,
                     const unsigned int seed, LocalizationRuntime* runtime) {
  colmap::SetPRNGSeed(seed);
  const Eigen::Vector2d center(0.5 * scene_options.image_width,
                               0.5 * scene_options.image_height);
  colmap::Timer timer;
  timer.Start();
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
      ++runtime->num_poses_correct;
    }
  }
  runtime->radial_pose_seconds_per_image =
      results.empty() ? 0 : timer.ElapsedSeconds() / results.size();
}

SyntheticMapDatabaseOptions SceneOptions(const RuntimeBenchmarkOptions& options,
                                         const ChildRequest& request,
                                         const LocalizationMode mode) {
  SyntheticMapDatabaseOptions scene_options;
  scene_options.num_map_images = options.map_images;
  scene_options.features_per_map_image = options.map_features;
  scene_options.points_per_map_image = options.map_points_per_image;
  scene_options.num_rig_images = mode == LocalizationMode::kDirect
                                     ? options.rig_images
                                     : options.retrieval_images;
  scene_options.features_per_rig_image = request.rig_features;
  scene_options.map_points_per_rig_image = request.rig_features / 2;
  scene_options.seed = static_cast<unsigned int>(options.seed);
  return scene_options;
}

// Times building the localizer (index) and localizing the rig images.
bool TimeLocalization(const MapLocalizerOptions& localizer_options,
                      const SyntheticMapDatabase& scene,
                      const DatabaseReader& reader,
                      std::vector<ImageLocalization>* results,
                      LocalizationRuntime* runtime, std::string* error) {
  colmap::Timer timer;
  double cpu_start = ProcessCpuSeconds();
  timer.Start();
  const std::unique_ptr<MapLocalizer> localizer =
      MapLocalizer::Create(localizer_options, scene.map, &reader, error);
  if (localizer == nullptr) return false;
  runtime->index_seconds = timer.ElapsedSeconds();
  runtime->index_cpu_seconds = ProcessCpuSeconds() - cpu_start;
  runtime->num_map_images = static_cast<int>(localizer->NumMapImages());
  runtime->num_map_points = static_cast<long>(localizer->NumMapPoints());
  runtime->num_indexed_descriptors =
      static_cast<long>(localizer->NumIndexedDescriptors());

  cpu_start = ProcessCpuSeconds();
  timer.Restart();
  if (!localizer->LocalizeImages(scene.rig_image_names, results, error)) {
    return false;
  }
  runtime->seconds = timer.ElapsedSeconds();
  runtime->cpu_seconds = ProcessCpuSeconds() - cpu_start;
  runtime->num_images = static_cast<int>(results->size());
  return true;
}

}  // namespace

bool MeasureLocalization(const RuntimeBenchmarkOptions& options,
                         const ChildRequest& request,
                         LocalizationRuntime* runtime, std::string* error) {
  *runtime = LocalizationRuntime();
  runtime->features_per_rig_image = request.rig_features;
  MapLocalizerOptions localizer_options;
  if (!LocalizationModeFromName(request.mode, &localizer_options.mode)) {
    *error = "unknown localization mode " + request.mode;
    return false;
  }
  runtime->mode = request.mode;
  localizer_options.num_threads = options.num_threads;
  localizer_options.progress_interval = 0;
  if (request.num_checks > 0) {
    localizer_options.index.num_checks = request.num_checks;
  }
  runtime->num_checks = localizer_options.index.num_checks;

  const SyntheticMapDatabaseOptions scene_options =
      SceneOptions(options, request, localizer_options.mode);
  const std::string database_path =
      (std::filesystem::path(request.work_dir) /
       ("map_" + request.mode + "_" + std::to_string(request.rig_features) +
        ".db"))
          .string();
  SyntheticMapDatabase scene;
  colmap::Timer timer;
  timer.Start();
  if (!WriteSyntheticMapDatabase(scene_options, database_path, &scene, error)) {
    return false;
  }
  std::cout << "    synthetic database written in " << std::fixed
            << std::setprecision(1) << timer.ElapsedSeconds() << " s"
            << std::endl;
  DatabaseReader reader;
  std::vector<ImageLocalization> results;
  if (!reader.Open(database_path, error) ||
      !TimeLocalization(localizer_options, scene, reader, &results, runtime,
                        error)) {
    return false;
  }
  ScoreCorrespondences(scene, results, runtime);
  TimeRadialPoses(scene_options, scene, results,
                  static_cast<unsigned int>(options.seed), runtime);
  reader.Close();
  std::filesystem::remove(database_path);
  return true;
}

}  // namespace rig_calibrator
