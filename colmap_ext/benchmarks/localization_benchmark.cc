#include "colmap_ext/benchmarks/localization_benchmark.h"

#include <colmap/util/random.h>
#include <colmap/util/timer.h>
#include <omp.h>
#include <sys/resource.h>

#include <iomanip>
#include <memory>
#include <set>
#include <sstream>

#include "colmap_ext/benchmarks/child_process.h"
#include "src/estimators/radial_pose_estimator.h"

namespace rig_calibrator {

std::vector<std::string> RigImageNames(const colmap::Reconstruction& map,
                                       const DatabaseReader& database) {
  std::set<std::string> map_names;
  for (const colmap::image_t image_id : map.RegImageIds()) {
    map_names.insert(map.Image(image_id).Name());
  }
  std::vector<std::string> names;
  for (const DatabaseImage& image : database.Images()) {
    if (map_names.count(image.name) == 0) names.push_back(image.name);
  }
  return names;
}

bool BenchmarkLocalization(const MapLocalizerOptions& options,
                           const colmap::Reconstruction& map,
                           const DatabaseReader& database,
                           const std::vector<std::string>& image_names,
                           const int min_num_inliers, const unsigned int seed,
                           LocalizationBenchmarkResult* result,
                           std::string* error) {
  *result = LocalizationBenchmarkResult();
  result->num_threads =
      options.num_threads > 0 ? options.num_threads : omp_get_max_threads();
  colmap::Timer timer;
  timer.Start();
  double cpu_start = ProcessCpuSeconds();
  const std::unique_ptr<MapLocalizer> localizer =
      MapLocalizer::Create(options, map, &database, error);
  if (localizer == nullptr) return false;
  result->index_seconds = timer.ElapsedSeconds();
  result->index_cpu_seconds = ProcessCpuSeconds() - cpu_start;
  result->num_map_images = static_cast<int>(localizer->NumMapImages());
  result->num_map_points = static_cast<long>(localizer->NumMapPoints());
  result->num_indexed_descriptors =
      static_cast<long>(localizer->NumIndexedDescriptors());

  std::vector<ImageLocalization> localizations;
  timer.Restart();
  cpu_start = ProcessCpuSeconds();
  if (!localizer->LocalizeImages(image_names, &localizations, error)) {
    return false;
  }
  result->seconds = timer.ElapsedSeconds();
  result->cpu_seconds = ProcessCpuSeconds() - cpu_start;
  result->num_images = static_cast<int>(localizations.size());

  for (const ImageLocalization& localization : localizations) {
    result->num_features += database.NumKeypoints(localization.image_id);
    result->num_correspondences +=
        static_cast<long>(localization.correspondences.size());
    result->num_index_queries += localization.num_index_queries;
    result->num_guided_queries += localization.num_guided_queries;
    DatabaseCamera camera;
    if (!database.ReadCamera(localization.camera_id, &camera, error)) {
      return false;
    }
    const Eigen::Vector2d center(0.5 * camera.width, 0.5 * camera.height);
    std::vector<Eigen::Vector2d> points2D;
    std::vector<Eigen::Vector3d> points3D;
    for (const Correspondence& correspondence : localization.correspondences) {
      points2D.push_back(correspondence.point2D - center);
      points3D.push_back(correspondence.point3D);
    }
    colmap::SetPRNGSeed(seed + 7919u * localization.image_id + 1u);
    RadialPoseEstimationOptions pose_options;
    pose_options.min_num_inliers = min_num_inliers;
    RadialPoseEstimate pose;
    if (EstimateRadialPose(pose_options, points2D, points3D, &pose)) {
      ++result->num_posed_images;
      result->num_inliers += pose.num_inliers;
    }
  }
  rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  result->peak_memory_mb = usage.ru_maxrss / 1024.0;
  return true;
}

std::string LocalizationBenchmarkCsvHeader() {
  return "label,threads,map_images,map_points,indexed_descriptors,images,"
         "features,index_s,index_cpu_s,localize_s,localize_cpu_s,images_per_s,"
         "cpu_utilization,correspondences,index_queries,guided_queries,"
         "posed_images,radial_inlier_ratio,peak_memory_mb,machine";
}

std::string LocalizationBenchmarkCsvRow(const std::string& label,
                                        const LocalizationBenchmarkResult& r,
                                        const std::string& machine) {
  std::ostringstream row;
  row << label << ',' << r.num_threads << ',' << r.num_map_images << ','
      << r.num_map_points << ',' << r.num_indexed_descriptors << ','
      << r.num_images << ',' << r.num_features << ',' << std::fixed
      << std::setprecision(3) << r.index_seconds << ',' << r.index_cpu_seconds
      << ',' << r.seconds << ',' << r.cpu_seconds << ',' << r.ImagesPerSecond()
      << ',' << r.CpuUtilization() << ',' << r.num_correspondences << ','
      << r.num_index_queries << ',' << r.num_guided_queries << ','
      << r.num_posed_images << ',' << std::setprecision(4) << r.InlierRatio()
      << ',' << std::setprecision(1) << r.peak_memory_mb << ",\"" << machine
      << '"';
  return row.str();
}

}  // namespace rig_calibrator
