// `rig_calibrator [calibrate]`: from a COLMAP database + map (or a 2D-3D
// correspondence file) to a calibrated rig in COLMAP's and Kalibr's formats.
// The options are in calibrate_options.h, the assembly of the calibration
// problem in calibration_input.h, what is reported in calibration_report.h.
#include <iostream>

#include "colmap_ext/commands/calibrate_options.h"
#include "colmap_ext/commands/calibration_input.h"
#include "colmap_ext/commands/calibration_report.h"
#include "colmap_ext/commands/command_options.h"
#include "colmap_ext/commands/commands.h"
#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/io/map_reader.h"
#include "colmap_ext/io/model_writer.h"

namespace rig_calibrator {
namespace {

// The map of --input_path (empty without one).
bool ReadInputMap(const CalibrateOptions& options, colmap::Reconstruction* map,
                  std::string* error) {
  if (options.input_path.empty()) return true;
  std::cout << "== Reading the map " << options.input_path << std::endl;
  if (!ReadMap(options.input_path, map, error)) return false;
  std::cout << "  " << map->NumRegImages() << " images, " << map->NumPoints3D()
            << " points" << std::endl;
  return true;
}

RigOutputOptions MakeOutputOptions(const CalibrateOptions& options) {
  RigOutputOptions output_options;
  output_options.output_type = options.output_type;
  output_options.overwrite = options.overwrite;
  for (const std::string& input :
       {options.database_path, options.image_path, options.input_path,
        options.correspondences_path}) {
    if (!input.empty()) output_options.input_paths.push_back(input);
  }
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
  OutputFolderOptions output_folder;
  output_folder.overwrite = options.overwrite;
  output_folder.input_paths = MakeOutputOptions(options).input_paths;
  if (!MakePipelineOptions(&options, &pipeline, &error) ||
      !CheckOutputFolderUsable(options.output_path, output_folder, &error) ||
      !ReadInputMap(options, &map, &error)) {
    return PrintError(error);
  }
  RigDataset dataset;
  RigLayout layout;
  const bool loaded =
      options.FromCorrespondences()
          ? LoadFromCorrespondences(options, &dataset, &layout, &error)
          : LoadFromDatabase(options, map, &dataset, &layout, &error);
  if (!loaded) return PrintError(error);

  RigCalibration calibration;
  PipelineReport report;
  if (!CalibrateRig(pipeline, dataset, &calibration, &report)) {
    PrintDiagnostics(report);
    return PrintError("calibration failed: " + report.error);
  }
  const CalibrationSummary summary = MakeCalibrationSummary(
      dataset, calibration, layout.camera_prefixes, report);
  std::vector<std::string> notes;
  if (!WriteRigOutput(options.output_path, map, dataset, calibration,
                      layout.camera_prefixes, summary,
                      MakeOutputOptions(options), &notes, &error)) {
    return PrintError("writing the output failed, nothing was written: " +
                      error);
  }
  PrintResult(dataset, report, summary, notes);
  std::cout << "\nOutputs in " << options.output_path
            << ": COLMAP model (open with `colmap gui --import_path` or "
               "`colmap model_analyzer --path`), rigs/frames and "
               "rig_config.json for COLMAP >= 3.12, "
               "rig_bundle_adjuster_config.json for COLMAP 3.8, camchain.yaml "
               "(Kalibr), calibration_summary.json, correspondences.txt."
            << std::endl;
  if (report.HasErrors()) {
    return PrintError("some cameras could not be calibrated (see above)");
  }
  return EXIT_SUCCESS;
}

}  // namespace rig_calibrator
