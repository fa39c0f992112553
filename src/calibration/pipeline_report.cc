#include "src/calibration/pipeline_report.h"

#include <sys/resource.h>

#include <algorithm>
#include <iostream>
#include <map>

namespace rig_calibrator {
namespace {

// User + system CPU time of the process so far (all threads).
double ProcessCpuSeconds() {
  rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

}  // namespace

std::string DiagnosticLevelName(Diagnostic::Level level) {
  switch (level) {
    case Diagnostic::Level::kInfo:
      return "info";
    case Diagnostic::Level::kWarning:
      return "warning";
    case Diagnostic::Level::kError:
      return "error";
  }
  return "unknown";
}

bool PipelineReport::HasErrors() const {
  return !error.empty() ||
         std::any_of(diagnostics.begin(), diagnostics.end(),
                     [](const Diagnostic& diagnostic) {
                       return diagnostic.level == Diagnostic::Level::kError;
                     });
}

void AddDiagnostic(PipelineReport* report, Diagnostic::Level level,
                   const std::string& code, const std::string& message,
                   std::vector<int> cameras, std::vector<int> framesets) {
  report->diagnostics.push_back(
      {level, code, message, std::move(cameras), std::move(framesets)});
}

std::string CameraList(const RigDataset& dataset,
                       const std::vector<int>& cameras) {
  std::string list;
  for (const int camera : cameras) {
    list += (list.empty() ? "" : ", ") + dataset.cameras[camera].name;
  }
  return list;
}

void DiagnoseLocalization(const RigDataset& dataset,
                          const RigCalibration& calibration,
                          PipelineReport* report) {
  const int num_cameras = static_cast<int>(dataset.cameras.size());
  std::vector<int> num_localized(num_cameras, 0);
  std::vector<int> num_shared(num_cameras, 0);
  std::map<int, std::vector<int>> localized_by_frameset;
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    if (!calibration.images[i].localized) continue;
    ++num_localized[dataset.images[i].camera_index];
    localized_by_frameset[dataset.images[i].frameset_index].push_back(
        dataset.images[i].camera_index);
  }
  for (const auto& [frameset, cameras] : localized_by_frameset) {
    if (cameras.size() < 2) continue;
    for (const int camera : cameras) ++num_shared[camera];
  }
  std::vector<int> never_localized, never_shared;
  for (int c = 0; c < num_cameras; ++c) {
    if (num_localized[c] == 0) {
      never_localized.push_back(c);
    } else if (num_shared[c] == 0) {
      never_shared.push_back(c);
    }
  }
  if (!never_localized.empty()) {
    AddDiagnostic(report, Diagnostic::Level::kWarning, "camera_not_localized",
                  "no image of camera(s) " +
                      CameraList(dataset, never_localized) +
                      " could be localized in the map (too few 2D-3D inliers): "
                      "they cannot be calibrated. Record more of the mapped "
                      "scene with them, or check their images and features.",
                  never_localized);
  }
  if (!never_shared.empty()) {
    AddDiagnostic(report, Diagnostic::Level::kWarning,
                  "camera_not_in_shared_frameset",
                  "camera(s) " + CameraList(dataset, never_shared) +
                      " were localized, but never in a frameset where another "
                      "camera was localized too: nothing ties them to the rig. "
                      "Record framesets in which they and other cameras see "
                      "the mapped scene together, and check that images "
                      "taken together form one frameset (same name in every "
                      "camera folder, or --RigCalibrator.timestamp_tolerance).",
                  never_shared);
  }
}

void SummarizeCalibration(const RigDataset& dataset,
                          const RigCalibration& calibration,
                          PipelineReport* report) {
  std::vector<int> uncalibrated;
  for (size_t c = 0; c < dataset.cameras.size(); ++c) {
    if (!calibration.camera_calibrated[c]) {
      uncalibrated.push_back(static_cast<int>(c));
    }
  }
  if (!uncalibrated.empty()) {
    AddDiagnostic(report, Diagnostic::Level::kError, "camera_not_calibrated",
                  "camera(s) " + CameraList(dataset, uncalibrated) +
                      " are not calibrated (see the warnings above)",
                  uncalibrated);
  }
  for (const ImageResult& image : calibration.images) {
    if (image.used) ++report->num_used;
  }
  for (const auto& rig_from_world : calibration.rig_from_world) {
    if (rig_from_world) ++report->num_framesets_posed;
  }
}

StageTimer::StageTimer(const std::string& name, bool print,
                       PipelineReport* report)
    : name_(name), report_(report), cpu_start_(ProcessCpuSeconds()) {
  if (print) std::cout << "== " << name << std::endl;
  timer_.Start();
}

StageTimer::~StageTimer() {
  report_->timings.push_back({name_, timer_.ElapsedSeconds(),
                              ProcessCpuSeconds() - cpu_start_,
                              num_iterations_});
}

}  // namespace rig_calibrator
