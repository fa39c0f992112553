// Fixtures of the report tests: a real calibration output folder (the model
// writer's scene, tests/colmap_ext/io/model_writer_scene.h) and issue 12's
// contract keys (contract_keys.json, hand-written after ISSUE12_SHARED.md)
// merged into its summary, so that every section of the report has data.
#pragma once

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "colmap_ext/io/model_writer.h"
#include "colmap_ext/report/report_page.h"
#include "tests/colmap_ext/io/model_writer_scene.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace testing {

// Writes the scene's calibration into `output` as the calibrate command does
// (report.html included when `with_report`); false with `error` on failure.
inline bool WriteSceneOutput(const Scene& scene, const std::string& output,
                             const bool with_report, std::string* error) {
  CalibrationSummary summary =
      SummarizeCalibration(scene.dataset, scene.calibration, {});
  summary.method = "1dr";
  summary.diagnostics.push_back("warning parallel_principal_axes: a warning");
  summary.timings.push_back({"localize", 1.5, 2.5, 0});
  RigOutputOptions options;
  if (with_report) options.finish_folder = &WriteReportHtml;
  return WriteRigOutput(output, scene.map, scene.dataset, scene.calibration, {},
                        summary, options, nullptr, error);
}

inline nlohmann::ordered_json ReadJsonFile(const std::string& path) {
  std::ifstream file(path);
  return nlohmann::ordered_json::parse(file);
}

// Adds every key of contract_keys.json to the summary in `folder`: the
// camera keys to each camera (params_stddev by its model), the top-level
// uncertainty_method and the diagnostics.
inline void MergeContractKeys(const std::string& folder) {
  const nlohmann::ordered_json fixture =
      ReadJsonFile(SourceDir() + "/tests/colmap_ext/report/contract_keys.json");
  const std::string path = folder + "/" + kSummaryFile;
  nlohmann::ordered_json summary = ReadJsonFile(path);
  summary["uncertainty_method"] = fixture["uncertainty_method"];
  for (const auto& diagnostic : fixture["diagnostics"]) {
    summary["diagnostics"].push_back(diagnostic);
  }
  for (auto& camera : summary["cameras"]) {
    for (const auto& [key, value] : fixture["camera_keys"].items()) {
      camera[key] = value;
    }
    camera["uncertainty"]["params_stddev"] =
        fixture["params_stddev_by_model"][camera["model"].get<std::string>()];
  }
  std::ofstream(path) << summary.dump(2) << "\n";
}

}  // namespace testing
}  // namespace rig_calibrator
