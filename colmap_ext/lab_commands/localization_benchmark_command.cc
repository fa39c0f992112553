// `rig_calibrator_lab benchmark_localization`: the localization's throughput on
// a COLMAP map (localization_benchmark.h), one configuration per run, so that
// scripts/benchmark_localization.sh can alternate configurations on the same
// data and its peak memory is the run's own:
//
//   rig_calibrator_lab benchmark_localization --database_path DB
//       --input_path MAP
//       [--label NAME] [--csv_path FILE] [--Localization.* ...]
//   rig_calibrator_lab benchmark_localization --write_synthetic_map DIR
//       --map_points N   (DIR/database.db and DIR/sparse: a synthetic map of
//                         about N points, synthetic_map_database.h)
#include <colmap/util/timer.h>

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>

#include "colmap_ext/benchmarks/child_process.h"
#include "colmap_ext/benchmarks/localization_benchmark.h"
#include "colmap_ext/benchmarks/synthetic_map_database.h"
#include "colmap_ext/commands/calibrate_options.h"
#include "colmap_ext/commands/command_options.h"
#include "colmap_ext/io/map_reader.h"
#include "colmap_ext/lab_commands/lab_commands.h"

namespace rig_calibrator {
namespace {

namespace po = boost::program_options;

struct BenchmarkLocalizationOptions {
  std::string database_path;
  std::string input_path;
  std::string label = "run";
  std::string csv_path;
  int max_images = 0;
  int min_num_inliers = 15;
  std::string write_synthetic_map;
  long map_points = 100000;
  int rig_images = 40;
  int features_per_rig_image = 4096;
};

int Fail(const std::string& message) {
  std::cerr << "rig_calibrator_lab benchmark_localization: " << message
            << std::endl;
  return EXIT_FAILURE;
}

// A synthetic map of about `map_points` points (each seen by 4 map images
// with 1200 points, as benchmark_runtime's 300-image map), written as
// DIR/database.db and the COLMAP binary model DIR/sparse.
int WriteSyntheticMap(const BenchmarkLocalizationOptions& options) {
  namespace fs = std::filesystem;
  SyntheticMapDatabaseOptions scene_options;
  scene_options.points_per_map_image = 1200;
  scene_options.features_per_map_image = 1200;
  scene_options.num_map_images = static_cast<int>(
      std::max<long>(scene_options.track_length + 1,
                     options.map_points * scene_options.track_length /
                         scene_options.points_per_map_image));
  scene_options.num_rig_images = options.rig_images;
  scene_options.features_per_rig_image = options.features_per_rig_image;
  scene_options.map_points_per_rig_image = options.features_per_rig_image / 2;
  const fs::path dir(options.write_synthetic_map);
  std::error_code fs_error;
  fs::create_directories(dir / "sparse", fs_error);
  if (fs_error) return Fail("cannot create " + (dir / "sparse").string());
  colmap::Timer timer;
  timer.Start();
  SyntheticMapDatabase scene;
  std::string error;
  if (!WriteSyntheticMapDatabase(scene_options, (dir / "database.db").string(),
                                 &scene, &error)) {
    return Fail(error);
  }
  scene.map.WriteBinary((dir / "sparse").string());
  std::cout << "synthetic map: " << scene.map.NumRegImages() << " images, "
            << scene.map.NumPoints3D() << " points, "
            << scene.rig_image_names.size() << " rig images of "
            << options.features_per_rig_image << " features in " << dir << " ("
            << std::fixed << std::setprecision(1) << timer.ElapsedSeconds()
            << " s)" << std::endl;
  return EXIT_SUCCESS;
}

int Benchmark(const BenchmarkLocalizationOptions& options,
              const CalibrateOptions& localization) {
  MapLocalizerOptions localizer_options;
  std::string error;
  if (!MakeLocalizerOptions(localization, &localizer_options, &error)) {
    return Fail(error);
  }
  localizer_options.progress_interval = 0;
  colmap::Reconstruction map;
  if (!ReadMap(options.input_path, &map, &error)) return Fail(error);
  DatabaseReader database;
  if (!database.Open(options.database_path, &error)) return Fail(error);
  std::vector<std::string> names = RigImageNames(map, database);
  if (names.empty()) {
    return Fail("the database " + options.database_path +
                " has no image that is not registered in the map " +
                options.input_path +
                ": extract the rig images' features "
                "into it first");
  }
  if (options.max_images > 0 &&
      names.size() > static_cast<size_t>(options.max_images)) {
    names.resize(options.max_images);
  }
  const std::string machine_before = MachineDescription();
  LocalizationBenchmarkResult result;
  if (!BenchmarkLocalization(
          localizer_options, map, database, names, options.min_num_inliers,
          static_cast<unsigned int>(localization.seed), &result, &error)) {
    return Fail(error);
  }
  std::cout << std::fixed << std::setprecision(2) << options.label << ": "
            << result.num_images << " images ("
            << result.num_features / std::max(1, result.num_images)
            << " features each) against " << result.num_map_points
            << " map points (" << result.num_indexed_descriptors
            << " descriptors, index " << result.index_seconds << " s, "
            << result.index_cpu_seconds << " CPU s) in " << result.seconds
            << " s, " << result.cpu_seconds
            << " CPU s: " << result.ImagesPerSecond()
            << " images/s, CPU utilization " << result.CpuUtilization()
            << " of " << result.num_threads << " threads; "
            << result.num_correspondences << " correspondences ("
            << result.num_index_queries << " features searched in the index, "
            << result.num_guided_queries << " matched along radial lines), "
            << result.num_posed_images << " images posed, radial inlier ratio "
            << std::setprecision(3) << result.InlierRatio() << ", peak memory "
            << std::setprecision(0) << result.peak_memory_mb << " MB; "
            << machine_before << std::endl;
  if (!options.csv_path.empty()) {
    const bool exists = std::filesystem::exists(options.csv_path);
    std::ofstream csv(options.csv_path, std::ios::app);
    if (!exists) csv << LocalizationBenchmarkCsvHeader() << '\n';
    csv << LocalizationBenchmarkCsvRow(options.label, result, machine_before)
        << '\n';
    if (!csv) return Fail("cannot write " + options.csv_path);
  }
  return EXIT_SUCCESS;
}

}  // namespace

int RunLocalizationBenchmark(int argc, char** argv) {
  BenchmarkLocalizationOptions options;
  CalibrateOptions localization;
  po::options_description description =
      CommandOptions("rig_calibrator_lab benchmark_localization options");
  AddOption(&description, "database_path", &options.database_path,
            "COLMAP database with the map and the rig images' features");
  AddOption(&description, "input_path", &options.input_path,
            "the map: a COLMAP sparse model folder");
  AddOption(&description, "label", &options.label, "name of the run");
  AddOption(&description, "csv_path", &options.csv_path,
            "CSV file to append the run's row to (header if new)");
  AddOption(&description, "max_images", &options.max_images,
            "localize at most this many rig images (0: all)");
  AddOption(&description, "min_num_inliers", &options.min_num_inliers,
            "radial pose inliers of a posed image");
  AddOption(&description, "num_threads", &localization.num_threads,
            "-1: all cores");
  AddOption(&description, "seed", &localization.seed, "random seed");
  AddOption(&description, "write_synthetic_map", &options.write_synthetic_map,
            "instead: write a synthetic map (database.db, sparse/) here");
  AddOption(&description, "map_points", &options.map_points,
            "synthetic map: about this many points");
  AddOption(&description, "rig_images", &options.rig_images,
            "synthetic map: rig images");
  AddOption(&description, "rig_features", &options.features_per_rig_image,
            "synthetic map: features per rig image");
  description.add(DescribeLocalizationOptions(&localization));
  if (const std::optional<int> exit_code = ParseCommandLine(
          argc, argv, description,
          "rig_calibrator_lab benchmark_localization: localization throughput "
          "on a COLMAP map")) {
    return *exit_code;
  }
  if (!options.write_synthetic_map.empty()) return WriteSyntheticMap(options);
  if (options.database_path.empty() || options.input_path.empty()) {
    return Fail(
        "give --database_path and --input_path (or "
        "--write_synthetic_map)");
  }
  return Benchmark(options, localization);
}

}  // namespace rig_calibrator
