// `rig_calibrator [calibrate]`: from a COLMAP database + map (or a 2D-3D
// correspondence file) to a calibrated rig in COLMAP's and Kalibr's formats.
// The options are in calibrate_options.h, the assembly of the calibration
// problem in calibration_input.h, what is reported in calibration_report.h.
#include <iostream>
#include <unordered_set>

#include "colmap_ext/commands/calibrate_options.h"
#include "colmap_ext/commands/calibration_input.h"
#include "colmap_ext/commands/calibration_report.h"
#include "colmap_ext/commands/command_options.h"
#include "colmap_ext/commands/commands.h"
#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/io/database_export.h"
#include "colmap_ext/io/map_reader.h"
#include "colmap_ext/io/model_writer.h"
#include "colmap_ext/report/report_page.h"

namespace rig_calibrator {
namespace {

// The map of --input_path (empty without one).
bool ReadInputMap(const CalibrateOptions& options, colmap::Reconstruction* map,
                  MapReadInfo* info, std::string* error) {
  if (options.input_path.empty()) return true;
  std::cout << "== Reading the map " << options.input_path << std::endl;
  if (!ReadMap(options.input_path, map, info, error)) return false;
  std::cout << "  " << map->NumRegImages() << " images, " << map->NumPoints3D()
            << " points" << std::endl;
  for (const std::string& note : info->notes) {
    std::cout << "  " << note << std::endl;
  }
  for (const std::string& warning : info->warnings) {
    std::cerr << "warning: " << warning << std::endl;
  }
  return true;
}

RigOutputOptions MakeOutputOptions(const CalibrateOptions& options,
                                   const MapReadInfo& map_info) {
  RigOutputOptions output_options;
  output_options.newer_model_map_cameras = map_info.newer_model_cameras;
  output_options.output_type = options.output_type;
  output_options.overwrite = options.overwrite;
  for (const std::string& input :
       {options.database_path, options.image_path, options.input_path,
        options.correspondences_path}) {
    if (!input.empty()) output_options.input_paths.push_back(input);
  }
  output_options.finish_folder = &WriteReportHtml;
  return output_options;
}

}  // namespace

int RunCalibrate(int argc, char** argv) {
  CalibrateOptions options;
  if (const std::optional<int> exit_code = ParseCommandLine(
          argc, argv, DescribeCalibrateOptions(&options),
          "rig_calibrator [calibrate]: calibrate a multi-camera rig against a "
          "COLMAP map")) {
    return *exit_code;
  }
  std::string error;
  PipelineOptions pipeline;
  colmap::Reconstruction map;
  MapReadInfo map_info;
  OutputFolderOptions output_folder;
  output_folder.overwrite = options.overwrite;
  output_folder.input_paths = MakeOutputOptions(options, map_info).input_paths;
  if (!MakePipelineOptions(&options, &pipeline, &error) ||
      !CheckOutputFolderUsable(options.output_path, output_folder, &error) ||
      !ReadInputMap(options, &map, &map_info, &error)) {
    return PrintError(error);
  }
  RigDataset dataset;
  RigLayout layout;
  KnownRigPrior known_rig;
  const bool loaded =
      options.FromCorrespondences()
          ? LoadFromCorrespondences(options, &dataset, &layout, &error)
          : LoadFromDatabase(options, map, &dataset, &layout, &error,
                             &known_rig);
  if (!loaded) return PrintError(error);
  std::unordered_set<colmap::camera_t> placeholder_cameras;
  for (const CameraRecord& camera : map_info.newer_model_cameras) {
    placeholder_cameras.insert(camera.camera_id);
  }
  if (const int num_left_out =
          AddMapImages(map, placeholder_cameras, &dataset)) {
    std::cout << "  " << num_left_out
              << " map image(s) of camera models newer than COLMAP 3.8 take "
                 "no part in the final adjustment and keep their input poses"
              << std::endl;
  }

  RigCalibration calibration;
  PipelineReport report;
  if (!CalibrateRig(pipeline, dataset, &calibration, &report)) {
    PrintDiagnostics(report);
    return PrintError("calibration failed: " + report.error);
  }
  CalibrationSummary summary =
      MakeCalibrationSummary(dataset, calibration, layout.camera_prefixes,
                             report, pipeline.seed, known_rig);
  for (const double offset : layout.timestamp_offsets) {
    summary.timestamp_offsets_s.push_back(offset * options.timestamp_unit_s);
  }
  std::vector<std::string> notes;
  if (!WriteRigOutput(options.output_path, map, dataset, calibration,
                      layout.camera_prefixes, summary,
                      MakeOutputOptions(options, map_info), &notes, &error)) {
    return PrintError("writing the output failed, nothing was written: " +
                      error);
  }
  PrintResult(dataset, report, summary, notes);
  if (!options.export_database.empty()) {
    DatabaseExportSummary exported;
    if (!ExportDatabaseWithRigMatches(options.database_path,
                                      options.export_database, map, dataset,
                                      calibration, &exported, &error)) {
      return PrintError("exporting the database failed: " + error);
    }
    std::cout << "\nDatabase for COLMAP in " << options.export_database << ": "
              << exported.num_matches << " matches of "
              << exported.num_rig_images << " rig images to the map images ("
              << exported.num_image_pairs << " image pairs), "
              << exported.num_cameras_updated
              << " rig cameras with the calibrated intrinsics";
    if (exported.num_unmatched_rows > 0) {
      std::cout << "; " << exported.num_unmatched_rows
                << " correspondences have no keypoint in the database";
    }
    std::cout << std::endl;
  }
  std::cout << "\nOutputs in " << options.output_path
            << ": COLMAP model (open with `colmap gui --import_path` or "
               "`colmap model_analyzer --path`), rigs/frames and "
               "rig_config.json for COLMAP >= 3.12, "
               "rig_bundle_adjuster_config.json for COLMAP 3.8, camchain.yaml "
               "(Kalibr), calibration_summary.json, correspondences.txt, "
               "timings.json, report.html (open it in a browser)."
            << std::endl;
  if (report.HasErrors()) {
    return PrintError(
        "some cameras could not be calibrated or have a camera model that is "
        "not valid over the whole image (see above)");
  }
  return EXIT_SUCCESS;
}

}  // namespace rig_calibrator
