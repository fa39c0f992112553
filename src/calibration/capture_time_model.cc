#include "src/calibration/capture_time_model.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "src/calibration/calibration_uncertainty.h"
#include "src/calibration/inlier_selection.h"
#include "src/calibration/time_offsets_from_rotations.h"

namespace rig_calibrator {
namespace {

// RMS of the reprojection error over the inliers of the used images.
double CalibrationRms(const RigCalibration& calibration) {
  double sum = 0;
  int64_t count = 0;
  for (const ImageResult& image : calibration.images) {
    if (!image.used) continue;
    sum += image.rms_px * image.rms_px * image.num_inliers;
    count += image.num_inliers;
  }
  return count > 0 ? std::sqrt(sum / count) : 0;
}

// The median interval between consecutive framesets (seconds), 0 with
// fewer than two.
double MedianFramesetInterval(const std::vector<double>& times_s) {
  std::vector<double> intervals;
  for (size_t f = 1; f < times_s.size(); ++f) {
    intervals.push_back(times_s[f] - times_s[f - 1]);
  }
  if (intervals.empty()) return 0;
  const size_t middle = intervals.size() / 2;
  std::nth_element(intervals.begin(), intervals.begin() + middle,
                   intervals.end());
  return intervals[middle];
}

// Beyond the floor and min_sigmas sigma; never without a sigma (the
// covariance failed; see the header).
bool Significant(double value, double sigma, double min_value,
                 const CaptureTimeModelOptions& options) {
  return std::abs(value) > min_value && std::isfinite(sigma) &&
         std::abs(value) > options.min_sigmas * sigma;
}

// The capture-timing estimate of camera c's offset, if observable, else 0.
std::vector<double> CaptureTimingStartOffsets(
    const CaptureTimeModelOptions& options, const RigDataset& dataset,
    const RigCalibration& calibration) {
  std::vector<double> offsets(dataset.cameras.size(), 0.0);
  const CaptureTiming timing = MeasureCaptureTiming(
      dataset, calibration, CalibrationUncertainty(), options.start_estimate);
  if (!timing.error.empty()) {
    LOG(INFO) << "Capture-time model: no capture-timing start ("
              << timing.error << ")";
    return offsets;
  }
  for (size_t c = 0; c < timing.offsets.size(); ++c) {
    if (timing.offsets[c].observable &&
        static_cast<int>(c) != dataset.reference_camera) {
      offsets[c] = timing.offsets[c].offset_s;
    }
  }
  return offsets;
}

// The sigmas of a time-model result: the calibration's uncertainty with
// its time model (calibration_uncertainty.h; NaN when it is not computed,
// with `error` saying why).
void EstimateCaptureTimeSigmas(const FinalBundleAdjustmentOptions& ba_options,
                          bool offsets, bool line_delays,
                          const RigDataset& dataset,
                          const RigCalibration& result,
                          std::vector<CameraCaptureTime>* times,
                          std::string* error) {
  const CalibrationUncertainty uncertainty = EstimateCalibrationUncertainty(
      WithCaptureTimes(ba_options, offsets, line_delays, *times), dataset,
      result);
  *error = uncertainty.computed ? "" : uncertainty.message;
  SetCaptureTimeSigmas(uncertainty, times);
}

// The start offsets (see the header): from the images' own orientations
// where found, else from the capture-timing estimate.
std::vector<double> EstimatedStartOffsets(const CaptureTimeModelOptions& options,
                                          const RigDataset& dataset,
                                          const RigCalibration& calibration) {
  const size_t num_cameras = dataset.cameras.size();
  RotationTimeOffsetProblem problem;
  problem.frameset_times_s = dataset.frameset_times_s;
  problem.reference_camera = dataset.reference_camera;
  problem.cam_from_world.assign(
      num_cameras, std::vector<std::optional<Eigen::Quaterniond>>(
                       dataset.frameset_names.size()));
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const std::optional<Rigid3d>& pose =
        calibration.images[i].single_image_cam_from_world;
    if (!pose) continue;
    problem.cam_from_world[dataset.images[i].camera_index]
                          [dataset.images[i].frameset_index] = pose->rotation;
  }
  std::vector<RotationTimeOffset> from_rotations;
  std::string error;
  if (!EstimateTimeOffsetsFromRotations(problem, options.rotation_start,
                                        &from_rotations, &error)) {
    LOG(INFO) << "Capture-time model: no start from the orientations ("
              << error << ")";
    from_rotations.assign(num_cameras, RotationTimeOffset());
  }
  std::vector<double> offsets(num_cameras, 0.0);
  std::vector<double> timing;
  for (size_t c = 0; c < num_cameras; ++c) {
    if (static_cast<int>(c) == dataset.reference_camera) continue;
    const RotationTimeOffset& rotation = from_rotations[c];
    if (rotation.found) {
      offsets[c] = rotation.offset_s;
      LOG(INFO) << "Capture-time model: " << dataset.cameras[c].name
                << " starts at " << offsets[c] * 1e3
                << " ms (its images' orientations, " << rotation.num_framesets
                << " framesets, median residual "
                << rotation.median_residual_rad * 180 / M_PI << " deg)";
      continue;
    }
    if (timing.empty()) {
      timing = CaptureTimingStartOffsets(options, dataset, calibration);
    }
    offsets[c] = timing[c];
    LOG(INFO) << "Capture-time model: " << dataset.cameras[c].name
              << " starts at " << offsets[c] * 1e3
              << " ms (the capture-timing estimate; not from the "
                 "orientations: "
              << rotation.diagnosis << ")";
  }
  return offsets;
}

// The time-model adjustment from `start` (today's parameters, its inliers
// re-selected), then once more with the inliers selected at each row's
// instant of that result: the start's are those within the threshold of
// the synchronized fit, which leaves out an unsynchronized camera's correct
// correspondences (tens of pixels off there; at 500 x 10 one camera kept
// 320 of 454 images). False when it failed.
bool AdjustWithTimeModel(const CaptureTimeModelOptions& options,
                         FinalBundleAdjustmentOptions ba_options,
                         bool offsets, bool line_delays,
                         const std::vector<double>& start_offsets,
                         const RigDataset& dataset, const RigCalibration& start,
                         RigCalibration* result,
                         FinalBundleAdjustmentSummary* summary) {
  ba_options.estimate_time_offsets = offsets;
  ba_options.estimate_line_delays = line_delays;
  ba_options.initial_time_offsets_s =
      offsets ? start_offsets : std::vector<double>();
  ba_options.initial_line_delays_s.clear();
  *result = start;
  SelectFullInliers(dataset, options.inlier_max_error_px, result);
  if (!AdjustRig(ba_options, dataset, result, summary)) return false;
  const FinalBundleAdjustmentOptions again = WithCaptureTimes(
      ba_options, offsets, line_delays, summary->capture_times);
  SelectFullInliers(dataset, options.inlier_max_error_px, result,
                    again.initial_time_offsets_s, again.initial_line_delays_s);
  return AdjustRig(again, dataset, result, summary);
}

std::string FormatCameras(const RigDataset& dataset,
                          const CaptureTimeModel& model) {
  std::ostringstream line;
  line << std::fixed;
  for (size_t c = 0; c < model.cameras.size(); ++c) {
    const CameraCaptureTime& time = model.cameras[c];
    if (!time.time_offset_estimated && !time.line_delay_estimated) continue;
    line << " " << dataset.cameras[c].name;
    if (time.time_offset_estimated) {
      line << std::setprecision(2) << std::showpos << " "
           << time.time_offset_s * 1e3 << std::noshowpos << " +- "
           << time.time_offset_sigma_s * 1e3 << " ms";
    }
    if (time.line_delay_estimated) {
      line << std::setprecision(2) << " " << time.line_delay_s * 1e6 << " +- "
           << time.line_delay_sigma_s * 1e6 << " us/row";
    }
    line << ";";
  }
  return line.str();
}

}  // namespace

FinalBundleAdjustmentOptions WithCaptureTimes(
    FinalBundleAdjustmentOptions ba_options, bool offsets, bool line_delays,
    const std::vector<CameraCaptureTime>& times) {
  ba_options.estimate_time_offsets = offsets;
  ba_options.estimate_line_delays = line_delays;
  ba_options.initial_time_offsets_s.clear();
  ba_options.initial_line_delays_s.clear();
  for (const CameraCaptureTime& time : times) {
    ba_options.initial_time_offsets_s.push_back(offsets ? time.time_offset_s
                                                        : 0.0);
    ba_options.initial_line_delays_s.push_back(
        line_delays ? time.line_delay_s : 0.0);
  }
  return ba_options;
}

FinalBundleAdjustmentOptions WithCaptureTimes(
    const FinalBundleAdjustmentOptions& ba_options,
    const CaptureTimeModel& model) {
  if (!model.computed ||
      (!model.time_offsets_kept && !model.line_delays_kept)) {
    return ba_options;
  }
  return WithCaptureTimes(ba_options, model.time_offsets_kept,
                          model.line_delays_kept, model.cameras);
}

void SetCaptureTimeSigmas(const CalibrationUncertainty& uncertainty,
                          std::vector<CameraCaptureTime>* times) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (size_t c = 0; c < times->size(); ++c) {
    CameraCaptureTime& time = (*times)[c];
    const bool computed = uncertainty.computed &&
                          c < uncertainty.cameras.size() &&
                          uncertainty.cameras[c].computed;
    if (time.time_offset_estimated) {
      time.time_offset_sigma_s =
          computed ? uncertainty.cameras[c].time_offset_stddev_s : nan;
    }
    if (time.line_delay_estimated) {
      time.line_delay_sigma_s =
          computed ? uncertainty.cameras[c].line_delay_stddev_s : nan;
    }
  }
}

bool CaptureTimeModeFromName(const std::string& name, CaptureTimeMode* mode) {
  for (const CaptureTimeMode value :
       {CaptureTimeMode::kOff, CaptureTimeMode::kOn, CaptureTimeMode::kAuto}) {
    if (CaptureTimeModeName(value) == name) {
      *mode = value;
      return true;
    }
  }
  return false;
}

std::string CaptureTimeModeName(CaptureTimeMode mode) {
  return mode == CaptureTimeMode::kOff  ? "0"
         : mode == CaptureTimeMode::kOn ? "1"
                                        : "auto";
}

bool AdjustRigWithCaptureTimeModel(const CaptureTimeModelOptions& options,
                                   const FinalBundleAdjustmentOptions&
                                       ba_options,
                                   const RigDataset& dataset,
                                   RigCalibration* calibration,
                                   CaptureTimeModel* model,
                                   std::string* error) {
  *model = CaptureTimeModel();
  const bool offsets_on = options.time_offsets == CaptureTimeMode::kOn;
  const bool shutter_on = options.rolling_shutter == CaptureTimeMode::kOn;
  const bool want_offsets = options.time_offsets != CaptureTimeMode::kOff;
  const bool want_shutter = options.rolling_shutter != CaptureTimeMode::kOff;
  if (!want_offsets && !want_shutter) return true;
  if (dataset.frameset_times_s.empty()) {
    if (offsets_on || shutter_on) {
      *error =
          "the capture-time model (--RigCalibrator.time_offsets 1 or "
          "rolling_shutter 1) needs frameset times, which this dataset does "
          "not have";
      return false;
    }
    return true;
  }
  if (!options.initial_time_offsets_s.empty() &&
      options.initial_time_offsets_s.size() != dataset.cameras.size()) {
    *error = "the capture-time model's start offsets are not one per camera";
    return false;
  }
  const double interval = MedianFramesetInterval(dataset.frameset_times_s);
  model->frameset_interval_s = interval;
  if (interval > options.max_frameset_interval_s) {
    std::ostringstream why;
    why << "the framesets are " << std::setprecision(3) << interval
        << " s apart (median), more than "
        << options.max_frameset_interval_s
        << " s: the rig's motion between them, which the model needs at "
           "each camera's own instant, is not known";
    if (!offsets_on && !shutter_on) {
      model->computed = true;
      model->rms_without_px = model->rms_px = CalibrationRms(*calibration);
      model->message = "not estimated: " + why.str() +
                       "; the calibration is the synchronized global-shutter "
                       "one (1 estimates anyway)";
      LOG(INFO) << "Capture-time model: " << model->message;
      return true;
    }
    LOG(WARNING) << "Capture-time model: " << why.str()
                 << "; estimated because it was asked for (1): treat the "
                    "offsets and line delays with suspicion";
  }
  const std::vector<double> start_offsets =
      !want_offsets ? std::vector<double>()
      : options.initial_time_offsets_s.empty()
          ? EstimatedStartOffsets(options, dataset, *calibration)
          : options.initial_time_offsets_s;

  model->computed = true;
  model->rms_without_px = CalibrationRms(*calibration);
  RigCalibration result;
  FinalBundleAdjustmentSummary summary;
  if (!AdjustWithTimeModel(options, ba_options, want_offsets, want_shutter,
                           start_offsets, dataset, *calibration, &result,
                           &summary)) {
    model->message = "the time-model adjustment failed (see the log)";
    if (offsets_on || shutter_on) {
      *error = "capture-time model: " + model->message;
      return false;
    }
    LOG(WARNING) << "Capture-time model: " << model->message
                 << "; the calibration keeps synchronized global shutters";
    return true;
  }

  const size_t num_cameras = dataset.cameras.size();
  model->cameras = summary.capture_times;
  EstimateCaptureTimeSigmas(ba_options, want_offsets, want_shutter, dataset, result,
                       &model->cameras, &model->sigma_error);
  model->time_offset_significant.assign(num_cameras, false);
  model->line_delay_significant.assign(num_cameras, false);
  bool any_offset = false, any_delay = false;
  for (size_t c = 0; c < num_cameras; ++c) {
    const CameraCaptureTime& time = model->cameras[c];
    model->time_offset_significant[c] =
        time.time_offset_estimated &&
        Significant(time.time_offset_s, time.time_offset_sigma_s,
                    options.min_offset_s, options);
    const double height = static_cast<double>(calibration->cameras[c].Height());
    model->line_delay_significant[c] =
        time.line_delay_estimated &&
        Significant(time.line_delay_s * height,
                    time.line_delay_sigma_s * height, options.min_readout_s,
                    options);
    any_offset = any_offset || model->time_offset_significant[c];
    any_delay = any_delay || model->line_delay_significant[c];
  }
  model->time_offsets_kept = offsets_on || (want_offsets && any_offset);
  model->line_delays_kept = shutter_on || (want_shutter && any_delay);
  std::ostringstream message;
  message << "estimated" << FormatCameras(dataset, *model) << " RMS "
          << std::setprecision(3) << model->rms_without_px << " -> "
          << summary.final_rms_px << " px; ";

  if (!model->time_offsets_kept && !model->line_delays_kept) {
    bool sigmas_missing = false;
    for (const CameraCaptureTime& time : model->cameras) {
      sigmas_missing = sigmas_missing ||
                       (time.time_offset_estimated &&
                        !std::isfinite(time.time_offset_sigma_s)) ||
                       (time.line_delay_estimated &&
                        !std::isfinite(time.line_delay_sigma_s));
    }
    message << "none significant (" << options.min_sigmas << " sigma, 1 ms"
            << (sigmas_missing ? "; no sigma (" + model->sigma_error +
                                     "), so none can be: 1 keeps them"
                               : std::string())
            << "): the calibration is the synchronized global-shutter one";
    model->rms_px = model->rms_without_px;
    model->message = message.str();
    LOG(INFO) << "Capture-time model: " << model->message;
    return true;
  }
  if (model->time_offsets_kept != want_offsets ||
      model->line_delays_kept != want_shutter) {
    // Auto dropped one kind: the adjustment again with the other alone.
    const std::vector<CameraCaptureTime> first = model->cameras;
    std::vector<double> kept_start;
    for (const CameraCaptureTime& time : first) {
      kept_start.push_back(time.time_offset_s);
    }
    if (!AdjustWithTimeModel(
            options, ba_options, model->time_offsets_kept,
            model->line_delays_kept,
            model->time_offsets_kept ? kept_start : std::vector<double>(),
            dataset, *calibration, &result, &summary)) {
      model->message = "the time-model adjustment failed (see the log)";
      model->time_offsets_kept = model->line_delays_kept = false;
      LOG(WARNING) << "Capture-time model: " << model->message;
      return true;
    }
    model->cameras = summary.capture_times;
    EstimateCaptureTimeSigmas(ba_options, model->time_offsets_kept,
                         model->line_delays_kept, dataset, result,
                         &model->cameras, &model->sigma_error);
  }
  message << "kept: "
          << (model->time_offsets_kept && model->line_delays_kept
                  ? "offsets and line delays"
              : model->time_offsets_kept ? "offsets"
                                         : "line delays");
  model->rms_px = summary.final_rms_px;
  model->message = message.str();
  LOG(INFO) << "Capture-time model: " << model->message;
  *calibration = std::move(result);
  return true;
}

std::vector<FramesetMotion> AdjustedFramesetMotions(
    const RigDataset& dataset, const RigCalibration& calibration) {
  std::vector<FramesetMotion> motions;
  std::string error;
  CHECK(ComputeFramesetMotions(dataset.frameset_times_s,
                               calibration.rig_from_world, &motions, &error,
                               calibration.frameset_motions_without_own_pose))
      << error << " (the capture-time model ran on these poses)";
  UseTranslationDerivatives(calibration.rig_translation_derivatives, &motions);
  return motions;
}

}  // namespace rig_calibrator
