// What report.html is made of, read from a calibration output folder only
// (colmap_ext/io/model_writer.h lists its files): the summary, the output
// COLMAP model with its rigs and frames, and camchain.yaml. The report needs
// nothing of the run that made the folder, so `rig_calibrator report` can
// rebuild it at any time.
#pragma once

#include <colmap/base/reconstruction.h>

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "colmap_ext/io/correspondence_io.h"
#include "colmap_ext/io/rigs_frames_io.h"

namespace rig_calibrator {

inline constexpr char kReportFile[] = "report.html";

struct ReportInputs {
  std::string folder;
  nlohmann::ordered_json summary;                  // calibration_summary.json
  colmap::Reconstruction model;                    // cameras, images, points3D
  std::optional<ColmapRigsAndFrames> rigs_frames;  // when the files exist
  std::string camchain_yaml;                       // empty when absent
  // correspondences.txt, read only when the model has no 3D points (a
  // calibration from correspondences without a map): the residuals then come
  // from its rows (model_residuals.h).
  std::vector<ImageCorrespondences> correspondences;
};

// Reads `folder`. Fails with a message naming the folder or file and what to
// do if the folder does not exist, the summary is missing, does not parse or
// has no "cameras" array, or the model (or its rigs/frames, or the
// correspondences it needs) cannot be read.
bool ReadReportInputs(const std::string& folder, ReportInputs* inputs,
                      std::string* error);

}  // namespace rig_calibrator
