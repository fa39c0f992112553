#include "src/calibration/camera_timing.h"

#include <cmath>
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
  // A sigma that could not be computed (NaN) reads "?".
  const auto sigma = [](double value, double unit) {
    std::ostringstream text;
    text << std::fixed << std::setprecision(2);
    if (std::isfinite(value)) {
      text << value * unit;
    } else {
      text << "?";
    }
    return text.str();
  };
  text << std::fixed << std::setprecision(2) << "dt " << std::showpos
       << timing.time_offset_s * 1e3 << std::noshowpos << " +- "
       << sigma(timing.time_offset_sigma_s, 1e3) << " ms";
  if (timing.line_delay_s_per_row) {
    text << " line " << *timing.line_delay_s_per_row * 1e6 << " +- "
         << sigma(timing.line_delay_sigma_s_per_row, 1e6) << " us/row";
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

std::vector<std::optional<CameraTiming>> AdjustedCameraTimings(
    const CaptureTimeModel& model) {
  if (!model.computed || (!model.time_offsets_kept && !model.line_delays_kept)) {
    return {};
  }
  std::vector<std::optional<CameraTiming>> timings(model.cameras.size());
  for (size_t c = 0; c < model.cameras.size(); ++c) {
    const CameraCaptureTime& time = model.cameras[c];
    CameraTiming& camera = timings[c].emplace();
    camera.source = TimingSource::kEstimatedInAdjustment;
    if (model.time_offsets_kept && time.time_offset_estimated) {
      camera.time_offset_s = time.time_offset_s;
      camera.time_offset_sigma_s = time.time_offset_sigma_s;
    }
    if (model.line_delays_kept && time.line_delay_estimated) {
      camera.line_delay_s_per_row = time.line_delay_s;
      camera.line_delay_sigma_s_per_row = time.line_delay_sigma_s;
    }
  }
  return timings;
}

}  // namespace rig_calibrator
