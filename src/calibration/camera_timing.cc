#include "src/calibration/camera_timing.h"

#include <iomanip>
#include <sstream>

namespace rig_calibrator {

std::string TimingSourceName(const TimingSource source) {
  switch (source) {
    case TimingSource::kMeasuredAfterCalibration:
      return "measured after calibration";
    case TimingSource::kEstimatedInAdjustment:
      return "estimated in the adjustment";
  }
  return "unknown";
}

std::optional<TimingSource> TimingSourceFromName(const std::string& name) {
  for (const TimingSource source : {TimingSource::kMeasuredAfterCalibration,
                                    TimingSource::kEstimatedInAdjustment}) {
    if (TimingSourceName(source) == name) return source;
  }
  return std::nullopt;
}

std::string CameraTimingText(const CameraTiming& timing) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(2) << "dt " << std::showpos
       << timing.time_offset_s * 1e3 << std::noshowpos << " +- "
       << timing.time_offset_sigma_s * 1e3 << " ms";
  if (timing.line_delay_s_per_row) {
    text << " line " << *timing.line_delay_s_per_row * 1e6 << " +- "
         << timing.line_delay_sigma_s_per_row * 1e6 << " us/row";
  }
  return text.str();
}

std::vector<std::optional<CameraTiming>> MeasuredCameraTimings(
    const CaptureTiming& timing, const int reference_camera) {
  if (!timing.computed || !timing.error.empty()) return {};
  std::vector<std::optional<CameraTiming>> timings(timing.offsets.size());
  bool any = false;
  for (size_t c = 0; c < timing.offsets.size(); ++c) {
    const CameraTimeOffset& offset = timing.offsets[c];
    if (static_cast<int>(c) == reference_camera || !offset.observable) {
      continue;
    }
    CameraTiming& camera = timings[c].emplace();
    camera.time_offset_s = offset.offset_s;
    camera.time_offset_sigma_s = offset.offset_sigma_s;
    any = true;
  }
  if (!any) return {};
  if (reference_camera >= 0 &&
      reference_camera < static_cast<int>(timings.size())) {
    timings[reference_camera].emplace();
  }
  return timings;
}

}  // namespace rig_calibrator
