// `rig_calibrator evaluate`: compares a calibration with a reference.
#include <boost/program_options.hpp>
#include <iostream>

#include "colmap_ext/commands/command_options.h"
#include "colmap_ext/commands/commands.h"
#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/io/rig_reference_io.h"
#include "src/evaluation/evaluation.h"

namespace rig_calibrator {
namespace {

namespace po = boost::program_options;

struct EvaluateOptions {
  std::string reference_path;
  std::string calibration_path;
  std::string output_path;
  bool align_scale = false;
  bool align_reference_camera = false;
};

// The estimate's cameras in the reference's order, matched by name. A
// camera without an image size (rig_config.json has none) takes the other
// side's.
bool MatchCameras(const RigDescription& reference,
                  const RigDescription& estimate,
                  std::vector<colmap::Camera>* reference_cameras,
                  std::vector<Rigid3d>* reference_cam_from_rig,
                  std::vector<colmap::Camera>* estimated_cameras,
                  std::vector<Rigid3d>* estimated_cam_from_rig,
                  std::vector<std::string>* names, std::string* error) {
  for (const RigDescriptionCamera& ref : reference.cameras) {
    const RigDescriptionCamera* match = nullptr;
    for (const RigDescriptionCamera& camera : estimate.cameras) {
      if (camera.name == ref.name) match = &camera;
    }
    if (match == nullptr || !match->camera || !match->cam_from_rig) {
      std::cout << "  " << ref.name
                << ": not in the calibration (or not calibrated there)\n";
      continue;
    }
    if (!ref.camera || !ref.cam_from_rig) {
      *error = "the reference has no intrinsics or pose for camera " + ref.name;
      return false;
    }
    colmap::Camera reference_camera = *ref.camera;
    colmap::Camera estimated_camera = *match->camera;
    if (reference_camera.Width() == 0) {
      reference_camera.SetWidth(estimated_camera.Width());
      reference_camera.SetHeight(estimated_camera.Height());
    }
    if (estimated_camera.Width() == 0) {
      estimated_camera.SetWidth(reference_camera.Width());
      estimated_camera.SetHeight(reference_camera.Height());
    }
    if (reference_camera.Width() == 0) {
      *error = "neither file gives the image size of camera " + ref.name +
               " (rig_config.json has none: pass an output folder or a "
               "camchain.yaml)";
      return false;
    }
    reference_cameras->push_back(reference_camera);
    reference_cam_from_rig->push_back(*ref.cam_from_rig);
    estimated_cameras->push_back(estimated_camera);
    estimated_cam_from_rig->push_back(*match->cam_from_rig);
    names->push_back(ref.name);
  }
  if (names->empty()) {
    *error =
        "the calibration and the reference have no camera in common "
        "(cameras are matched by name, i.e. image prefix)";
    return false;
  }
  return true;
}

}  // namespace

int RunEvaluate(int argc, char** argv) {
  EvaluateOptions options;
  po::options_description description =
      CommandOptions("rig_calibrator evaluate options");
  AddRequiredOption(&description, "reference_path", &options.reference_path,
                    "reference calibration: rig_calibrator output folder, "
                    "rig_config.json or camchain.yaml");
  AddRequiredOption(&description, "calibration_path", &options.calibration_path,
                    "calibration to evaluate, in the same formats");
  AddUnsetOption(&description, "output_path", &options.output_path,
                 "write the errors as JSON to this file");
  AddOption(&description, "align_scale", &options.align_scale,
            "also align the scale (for calibrations against non-metric maps)");
  AddOption(&description, "align_reference_camera",
            &options.align_reference_camera,
            "align the rigs by their reference cameras instead of all cameras");
  if (const std::optional<int> exit_code = ParseCommandLine(
          argc, argv, description,
          "rig_calibrator evaluate: compare a calibration with a reference "
          "calibration")) {
    return *exit_code;
  }

  std::string error;
  RigDescription reference, estimate;
  if (!ReadRigReference(options.reference_path, &reference, &error) ||
      !ReadRigReference(options.calibration_path, &estimate, &error)) {
    return PrintError(error);
  }
  std::vector<colmap::Camera> reference_cameras, estimated_cameras;
  std::vector<Rigid3d> reference_cam_from_rig, estimated_cam_from_rig;
  std::vector<std::string> names;
  if (!MatchCameras(reference, estimate, &reference_cameras,
                    &reference_cam_from_rig, &estimated_cameras,
                    &estimated_cam_from_rig, &names, &error)) {
    return PrintError(error);
  }
  CompareOptions compare;
  compare.align_scale = options.align_scale;
  compare.alignment = options.align_reference_camera
                          ? RigAlignment::kReferenceCamera
                          : RigAlignment::kAllCameras;
  const CalibrationError errors =
      CompareCalibrations(reference_cameras, reference_cam_from_rig,
                          estimated_cameras, estimated_cam_from_rig, compare);
  if (!errors.ok()) {
    return PrintError(errors.error);
  }
  std::cout << "Calibration " << options.calibration_path << "\nagainst "
            << options.reference_path << "\n\n"
            << FormatCalibrationErrorTable(errors, names) << std::endl;
  if (!options.output_path.empty() &&
      !WriteFileAtomically(options.output_path,
                           CalibrationErrorToJson(errors, names).dump(2) + "\n",
                           &error)) {
    return PrintError(error);
  }
  return EXIT_SUCCESS;
}

}  // namespace rig_calibrator
