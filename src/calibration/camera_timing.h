// Each camera's capture timing as the outputs show it (terminal table,
// calibration_summary.json, camchain.yaml, report.html), whichever step
// produced it:
//   time offset delta_c: camera c takes frameset f at t_f + delta_c, t_f the
//     frameset's time on the reference camera's clock (delta_ref = 0);
//   line delay rho_c: a rolling shutter exposes image row v at
//     t_f + delta_c + rho_c * v (seconds per row; absent: not estimated);
// each with its standard deviation, and where the numbers come from:
//   measured after calibration   capture_timing.h, from the images' own
//                                poses after an adjustment that assumed
//                                synchronized global-shutter cameras: the
//                                offsets are lower bounds (its header says
//                                why), and there is no line delay;
//   estimated in the adjustment  the final adjustment with the time model,
//                                delta_c and rho_c among its parameters.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "src/calibration/capture_time_model.h"
#include "src/calibration/capture_timing.h"

namespace rig_calibrator {

enum class TimingSource { kMeasuredAfterCalibration, kEstimatedInAdjustment };

struct CameraTiming {
  double time_offset_s = 0;        // delta_c
  double time_offset_sigma_s = 0;  // 0 for the reference camera (defined)
  std::optional<double> line_delay_s_per_row;  // rho_c; absent: not estimated
  double line_delay_sigma_s_per_row = 0;
  TimingSource source = TimingSource::kMeasuredAfterCalibration;
};

// "measured after calibration", "estimated in the adjustment" (the words
// written in the outputs).
std::string TimingSourceName(TimingSource source);
// The inverse of TimingSourceName; nullopt for any other text.
std::optional<TimingSource> TimingSourceFromName(const std::string& name);

// "dt +48.20 +- 0.31 ms" and, when estimated, " line 29.10 +- 0.40 us/row"
// (the result table's columns).
std::string CameraTimingText(const CameraTiming& timing);

// Per dataset camera the timing of capture_timing's measurement: the
// observable offsets with their sigma (source: measured after calibration),
// the reference camera's 0 +- 0 when any other camera has one; nothing
// (empty vector) when the step did not run or failed, nothing for a camera
// whose offset is not observable.
std::vector<std::optional<CameraTiming>> MeasuredCameraTimings(
    const CaptureTiming& timing, int reference_camera);

// Per dataset camera the timing of the final adjustment's time model
// (source: estimated in the adjustment) when it kept offsets or line delays:
// the kept kinds' values and sigmas (a sigma NaN when the covariance could not
// be computed); offsets not kept are 0 +- 0 (the adjustment assumed them),
// line delays not kept are absent. Nothing (empty vector) when the model kept
// neither.
std::vector<std::optional<CameraTiming>> AdjustedCameraTimings(
    const CaptureTimeModel& model);

}  // namespace rig_calibrator
