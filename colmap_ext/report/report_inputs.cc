#include "colmap_ext/report/report_inputs.h"

#include <boost/filesystem.hpp>
#include <fstream>
#include <sstream>

#include "colmap_ext/io/map_reader.h"
#include "colmap_ext/io/model_writer.h"

namespace rig_calibrator {
namespace {

bool ReadText(const std::string& path, std::string* text) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return false;
  std::ostringstream contents;
  contents << file.rdbuf();
  *text = contents.str();
  return static_cast<bool>(file) || file.eof();
}

bool HasRigsAndFrames(const std::string& folder) {
  for (const char* extension : {".bin", ".txt"}) {
    if (boost::filesystem::exists(folder + "/rigs" + extension) &&
        boost::filesystem::exists(folder + "/frames" + extension)) {
      return true;
    }
  }
  return false;
}

}  // namespace

bool ReadReportInputs(const std::string& folder, ReportInputs* inputs,
                      std::string* error) {
  inputs->folder = folder;
  boost::system::error_code code;
  if (!boost::filesystem::is_directory(folder, code)) {
    *error = "no calibration output folder at " + folder +
             " (give the --output_path of a rig_calibrator calibration)";
    return false;
  }
  const std::string summary_path = folder + "/" + kSummaryFile;
  std::string text;
  if (!ReadText(summary_path, &text)) {
    *error = "cannot read " + summary_path + ": is " + folder +
             " the output folder of a calibration?";
    return false;
  }
  inputs->summary = nlohmann::ordered_json::parse(text, nullptr, false);
  if (inputs->summary.is_discarded()) {
    *error = summary_path + " is not valid JSON";
    return false;
  }
  if (!inputs->summary.is_object() || !inputs->summary.contains("cameras") ||
      !inputs->summary["cameras"].is_array()) {
    *error = summary_path + " has no \"cameras\" array";
    return false;
  }
  std::string model_error;
  MapReadInfo model_info;
  if (!ReadModel(folder, &inputs->model, &model_info, &model_error)) {
    *error = "cannot read the COLMAP model in " + folder + ": " + model_error;
    return false;
  }
  if (HasRigsAndFrames(folder)) {
    ColmapRigsAndFrames& rigs_frames = inputs->rigs_frames.emplace();
    if (!ReadRigsAndFrames(folder, &rigs_frames, &model_error)) {
      *error =
          "cannot read the rigs and frames in " + folder + ": " + model_error;
      return false;
    }
  }
  const std::string correspondences_path = folder + "/" + kCorrespondencesFile;
  if (inputs->model.NumPoints3D() == 0 &&
      boost::filesystem::exists(correspondences_path) &&
      !ReadCorrespondenceFile(correspondences_path, &inputs->correspondences,
                              error)) {
    return false;
  }
  const std::string camchain_path = folder + "/" + kCamchainFile;
  if (boost::filesystem::exists(camchain_path) &&
      !ReadText(camchain_path, &inputs->camchain_yaml)) {
    *error = "cannot read " + camchain_path;
    return false;
  }
  return true;
}

}  // namespace rig_calibrator
