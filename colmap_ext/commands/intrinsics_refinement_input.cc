#include "colmap_ext/commands/intrinsics_refinement_input.h"

#include <algorithm>
#include <boost/algorithm/string.hpp>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "colmap_ext/io/rig_reference_io.h"

namespace rig_calibrator {
namespace {

// One switch for every camera: "1", "0" or "cam0:0,cam1:1" (a bare value is
// the default of the cameras not named; without one they are refined).
bool ParseSwitch(const std::string& option, const std::string& value,
                 const RigDataset& dataset, std::vector<bool>* refine,
                 std::string* error) {
  const size_t num_cameras = dataset.cameras.size();
  std::vector<std::optional<bool>> named(num_cameras);
  std::optional<bool> default_value;
  std::vector<std::string> items;
  boost::split(items, value, boost::is_any_of(","));
  for (std::string item : items) {
    boost::trim(item);
    if (item.empty()) continue;
    const size_t colon = item.find(':');
    std::string flag =
        colon == std::string::npos ? item : item.substr(colon + 1);
    boost::trim(flag);
    if (flag != "0" && flag != "1") {
      *error = "--RigCalibrator." + option +
               " takes 0 or 1, for every camera "
               "or per camera (cam0:0,cam1:1), not '" +
               item + "'";
      return false;
    }
    if (colon == std::string::npos) {
      default_value = flag == "1";
      continue;
    }
    std::string camera = item.substr(0, colon);
    boost::trim(camera);
    size_t c = 0;
    while (c < num_cameras && dataset.cameras[c].name != camera) ++c;
    if (c == num_cameras) {
      *error = "--RigCalibrator." + option + " names camera '" + camera +
               "', which is not a camera of the rig";
      return false;
    }
    named[c] = flag == "1";
  }
  refine->assign(num_cameras, true);
  for (size_t c = 0; c < num_cameras; ++c) {
    (*refine)[c] = named[c].value_or(default_value.value_or(true));
  }
  return true;
}

// The given intrinsics of every camera for the methods that estimate them
// (see the header): --RigCalibrator.intrinsics_path, else the database
// camera of the camera's first image when it has a prior focal length.
bool GivenIntrinsics(
    const CalibrateOptions& options,
    const std::map<std::string, DatabaseCamera>& database_cameras,
    const RigDataset& dataset,
    std::vector<std::optional<colmap::Camera>>* given,
    std::vector<std::string>* sources, std::string* error) {
  given->assign(dataset.cameras.size(), std::nullopt);
  sources->assign(dataset.cameras.size(), "");
  if (!options.intrinsics_path.empty()) {
    RigDescription rig;
    if (!ReadRigReference(options.intrinsics_path, &rig, error)) return false;
    for (size_t c = 0; c < dataset.cameras.size(); ++c) {
      for (const RigDescriptionCamera& camera : rig.cameras) {
        if (camera.name == dataset.cameras[c].name && camera.camera) {
          (*given)[c] = *camera.camera;
          (*sources)[c] =
              "--RigCalibrator.intrinsics_path " + options.intrinsics_path;
        }
      }
    }
    return true;
  }
  for (const RigImage& image : dataset.images) {
    const int c = image.camera_index;
    const auto it = database_cameras.find(image.name);
    if ((*given)[c] || it == database_cameras.end() ||
        !it->second.prior_focal_length || !it->second.known_to_colmap38) {
      continue;
    }
    colmap::Camera camera;
    std::string ignored;
    if (ToColmapCamera(it->second, &camera, &ignored)) {
      (*given)[c] = camera;
      (*sources)[c] = "the database camera of " + image.name;
    }
  }
  return true;
}

// Copies the parameters that `refinement` holds from `given` into *camera:
// the principal point always, the focal lengths when their counts agree (or
// one given focal length for fx and fy), the distortion for the same model.
bool CopyHeldParams(const colmap::Camera& given, const std::string& source,
                    const IntrinsicsRefinement& refinement,
                    const std::string& name, colmap::Camera* camera,
                    std::string* error) {
  const std::string what = "the intrinsics of camera " + name + " (" + source +
                           ", " + given.ModelName() + ")";
  if (given.Width() != 0 && (given.Width() != camera->Width() ||
                             given.Height() != camera->Height())) {
    *error = what + " are for " + std::to_string(given.Width()) + "x" +
             std::to_string(given.Height()) + " images, but its images are " +
             std::to_string(camera->Width()) + "x" +
             std::to_string(camera->Height()) +
             ": give intrinsics calibrated at the images' size";
    return false;
  }
  if (!refinement.principal_point) {
    camera->SetPrincipalPointX(given.PrincipalPointX());
    camera->SetPrincipalPointY(given.PrincipalPointY());
  }
  if (!refinement.focal_length) {
    const std::vector<size_t>& from = given.FocalLengthIdxs();
    const std::vector<size_t>& to = camera->FocalLengthIdxs();
    if (from.size() != to.size() && from.size() != 1) {
      *error = what + " has " + std::to_string(from.size()) +
               " focal lengths, model " + camera->ModelName() + " has " +
               std::to_string(to.size()) +
               ": give the intrinsics in the camera's model to hold its "
               "focal length (--RigCalibrator.refine_focal_length 0)";
      return false;
    }
    for (size_t k = 0; k < to.size(); ++k) {
      camera->Params(to[k]) = given.Params(from[from.size() == 1 ? 0 : k]);
    }
  }
  if (!refinement.extra_params) {
    if (given.ModelId() != camera->ModelId()) {
      *error = what + " are not of its model " + camera->ModelName() +
               ": give the intrinsics in that model to hold its distortion "
               "(--RigCalibrator.refine_extra_params 0)";
      return false;
    }
    for (const size_t i : camera->ExtraParamsIdxs()) {
      camera->Params(i) = given.Params(i);
    }
  }
  return true;
}

}  // namespace

bool SetIntrinsicsRefinement(
    const CalibrateOptions& options,
    const std::map<std::string, DatabaseCamera>& database_cameras,
    RigDataset* dataset, std::string* error) {
  std::vector<bool> focal, principal_point, extra;
  if (!ParseSwitch("refine_focal_length", options.refine_focal_length, *dataset,
                   &focal, error) ||
      !ParseSwitch("refine_principal_point", options.refine_principal_point,
                   *dataset, &principal_point, error) ||
      !ParseSwitch("refine_extra_params", options.refine_extra_params, *dataset,
                   &extra, error)) {
    return false;
  }
  bool holds_any = false;
  for (size_t c = 0; c < dataset->cameras.size(); ++c) {
    dataset->cameras[c].refinement = {focal[c], principal_point[c], extra[c]};
    holds_any = holds_any || !focal[c] || !principal_point[c] || !extra[c];
  }
  // The known* methods run with the given intrinsics: they are the values.
  if (!holds_any || options.KnownIntrinsics()) return true;
  std::vector<std::optional<colmap::Camera>> given;
  std::vector<std::string> sources;
  if (!GivenIntrinsics(options, database_cameras, *dataset, &given, &sources,
                       error)) {
    return false;
  }
  for (size_t c = 0; c < dataset->cameras.size(); ++c) {
    RigCamera& camera = dataset->cameras[c];
    if (given[c]) {
      // A held focal length or distortion belongs to the given model: an
      // automatic choice takes it.
      if (camera.choose_model && (!camera.refinement.focal_length ||
                                  !camera.refinement.extra_params)) {
        camera.choose_model = false;
        camera.camera.InitializeWithName(
            given[c]->ModelName(), camera.camera.MeanFocalLength(),
            camera.camera.Width(), camera.camera.Height());
        std::cout << "camera " << camera.name << ": model "
                  << given[c]->ModelName() << " from " << sources[c]
                  << " (its intrinsics are held), not chosen automatically"
                  << std::endl;
      }
      if (!CopyHeldParams(*given[c], sources[c], camera.refinement, camera.name,
                          &camera.camera, error)) {
        return false;
      }
    } else if (!camera.refinement.focal_length) {
      *error =
          "--RigCalibrator.refine_focal_length 0 holds the focal length of "
          "camera " +
          camera.name +
          ", but no focal length is given for it: give "
          "--RigCalibrator.intrinsics_path (a rig_config.json or "
          "camchain.yaml with its intrinsics), or extract its features with "
          "--ImageReader.camera_model and --ImageReader.camera_params, or "
          "refine it (--RigCalibrator.refine_focal_length " +
          camera.name + ":1)";
      return false;
    }
  }
  return true;
}

}  // namespace rig_calibrator
