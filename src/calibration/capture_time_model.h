// The capture-time model of the calibration (pipeline step after the final
// bundle adjustment, --RigCalibrator.time_offsets / rolling_shutter): the
// final adjustment again with per-camera capture-time offsets delta_c and
// line delays rho_c (final_bundle_adjuster.h, its time model), kept when
// asked for or when the data show them.
//
// Modes, per kind (offsets, line delays): off, the kind is not estimated;
// on, it is estimated and kept; auto, it is estimated and kept only when
// some camera's is significant:
//   offset:     |delta_c| > min_sigmas sigma(delta_c) and |delta_c| >
//               min_offset_s (1 ms: below it a sub-millisecond offset is
//               not told apart from the model's and the map's errors, and a
//               hardware-triggered rig is synchronized to well below that);
//   line delay: |rho_c| > min_sigmas sigma(rho_c) and |rho_c| * height_c >
//               min_readout_s (the readout time of the whole image, 1 ms).
// The sigmas are the calibration's uncertainty with the time model
// (calibration_uncertainty.h: the larger of the noise and the
// between-framesets estimate, the map, rig poses and intrinsics
// marginalized). Without them (the uncertainty not computed) nothing is
// significant: auto keeps nothing (`1` still keeps). A drop of the RMS is no
// evidence on real data, whose residuals are correlated: on the real ring a
// 5 % drop kept offsets of up to 10.6 ms that changed from one held-out
// split to the next (docs/time_model.md, "The time model on the real ring").
// A kind that is kept is kept for every camera (the values of the cameras
// where it is not significant are estimates near 0, not zeros); when auto
// keeps one kind and drops the other, the adjustment runs again with the
// kept one alone; when it keeps none, the calibration is today's (the
// adjustment without time model), unchanged to the bit.
//
// Start. The adjustment starts from today's result (its parameters, and
// the inliers re-selected within inlier_max_error_px of it, as the final
// adjustment's own start), the line delays at 0, the offsets at
// initial_time_offsets_s when given, else per camera at the offset that
// the orientations of its images' single-image localizations give against
// the reference camera's (time_offsets_from_rotations.h). Those rotations
// depend neither on the intrinsics nor on synchronization (for 1dr, the
// default, they need only the principal point), so the start needs no
// synchronization, unlike the capture-timing estimate from each image's pose
// with today's intrinsics (capture_timing.h), which is biased toward 0
// (today's intrinsics absorbed part of the motion). That estimate (for the
// cameras it finds observable, else 0) is the start only of the cameras
// whose orientations give no offset (a rig that hardly turns, too few
// framesets).
//
// Without frameset times the model cannot run: auto and off change nothing,
// on is an error. Nor can it follow the rig between framesets that are far
// apart in time: the motion model (frameset_motion.h) is a polynomial
// through the five nearest frameset poses, which follows motion up to a
// fraction of the frameset rate (at 5 Hz the synthetic walk's 2.3 Hz bob is
// not followed); a hand-held or vehicle rig moves at 1-2 Hz (gait, sway).
// With framesets further apart than max_frameset_interval_s (median) the
// rig's velocity at each frameset is a guess, and the offsets absorb
// whatever differs between framesets: on the real 5-camera ring (framesets
// 5.5 s apart) auto kept offsets of up to 10.6 ms with sigmas of 0.1-0.5
// ms that changed by up to 16 ms from one held-out split to the next
// (docs/time_model.md). auto then does not estimate (and says why); on
// estimates anyway and warns. The time model's adjustment runs on the final adjustment's
// backend (both have the time parameters).
#pragma once

#include <string>
#include <vector>

#include "src/calibration/calibration_uncertainty.h"
#include "src/calibration/capture_timing.h"
#include "src/calibration/final_bundle_adjuster.h"
#include "src/calibration/time_offsets_from_rotations.h"
#include "src/geometry/frameset_motion.h"

namespace rig_calibrator {

enum class CaptureTimeMode { kOff, kOn, kAuto };

// Parses/prints "0", "1", "auto".
bool CaptureTimeModeFromName(const std::string& name, CaptureTimeMode* mode);
std::string CaptureTimeModeName(CaptureTimeMode mode);

struct CaptureTimeModelOptions {
  CaptureTimeMode time_offsets = CaptureTimeMode::kAuto;
  CaptureTimeMode rolling_shutter = CaptureTimeMode::kAuto;
  // The significance test of auto (see the top).
  double min_sigmas = 3.0;
  double min_offset_s = 1e-3;
  double min_readout_s = 1e-3;
  // Above this median interval between consecutive framesets auto does not
  // run (see the top).
  double max_frameset_interval_s = 0.5;
  // Above this median interval the pipeline warns when offsets are kept
  // (time_model_framesets_sparse): the framesets do not follow the rig's
  // motion, and the velocity error common to all framesets, which moves
  // each camera's centre by its offset times it, is held by the estimates'
  // prior alone. Over synthetic seeds (scripts/benchmark_time_model_seeds.sh,
  // 1080 rows, offsets in +-50 ms) the ring's rotation errors were 1.46
  // times their sigma (RMS) at 5 Hz (5 seeds) and 1.48 at 10 Hz (5 seeds),
  // 1.89 and 1.34 times the same rig's synchronized; at 15 Hz (8 seeds)
  // 1.22 and 1.25 times (synchronized: 1.0-1.2 sigma). The threshold lies
  // between 15 Hz (0.067 s) and 10 Hz (0.1 s).
  double max_followed_frameset_interval_s = 0.08;
  // Inliers of the start: within this reprojection error of today's result
  // (the pipeline sets the final adjustment's own threshold).
  double inlier_max_error_px = 10.0;
  // Start offsets per dataset camera (reference 0); empty: from the
  // capture-timing estimate (see the top).
  std::vector<double> initial_time_offsets_s;
  // The start from the images' orientations, and the capture-timing
  // estimate where it finds none.
  RotationTimeOffsetOptions rotation_start;
  CaptureTimingOptions start_estimate;
};

// What the step did (PipelineReport::capture_time_model; in the summary's
// "capture_time_model").
struct CaptureTimeModel {
  // False when the step did not run (no frameset times, or both kinds off):
  // nothing below is set. With framesets too far apart for auto (see the
  // top) it is true with only `message` and the RMS set.
  bool computed = false;
  // Which kinds the calibration now models (false: not estimated, or
  // estimated and dropped by auto).
  bool time_offsets_kept = false;
  bool line_delays_kept = false;
  // Per dataset camera, the estimate of the last time-model adjustment
  // (values and sigmas), and per camera whether each is significant.
  std::vector<CameraCaptureTime> cameras;
  std::vector<bool> time_offset_significant;
  std::vector<bool> line_delay_significant;
  // The adjustment's RMS (pixels) with the time model, and today's.
  double rms_px = 0, rms_without_px = 0;
  // The median interval between consecutive framesets (seconds).
  double frameset_interval_s = 0;
  // Why the sigmas are NaN, when they are (the uncertainty's message).
  std::string sigma_error;
  // One line: what was estimated and kept, and why.
  std::string message;
};

// ba_options with the time model of `times` (values per dataset camera):
// the kinds asked for estimated, at those values (the rest 0).
FinalBundleAdjustmentOptions WithCaptureTimes(
    FinalBundleAdjustmentOptions ba_options, bool offsets, bool line_delays,
    const std::vector<CameraCaptureTime>& times);
// ba_options with the kinds `model` kept, at its values; unchanged when it
// kept none: the adjustment whose result the calibration is (for its
// uncertainty).
FinalBundleAdjustmentOptions WithCaptureTimes(
    const FinalBundleAdjustmentOptions& ba_options,
    const CaptureTimeModel& model);

// The sigmas of the estimated offsets and line delays of `times` from the
// calibration's uncertainty with the time model (NaN where it was not
// computed).
void SetCaptureTimeSigmas(const CalibrationUncertainty& uncertainty,
                          std::vector<CameraCaptureTime>* times);

// The rig's motion at every frameset as the time-model adjustment has it
// (frameset_motion.h): the polynomial through the calibration's frameset
// poses, its velocity and acceleration the estimated ones
// (RigCalibration::rig_translation_derivatives; the polynomial's while there
// are none). For poses the time model runs on
// (CHECK-fails when the motions cannot be computed, which those exclude).
std::vector<FramesetMotion> AdjustedFramesetMotions(
    const RigDataset& dataset, const RigCalibration& calibration);

// The step above. `calibration` is today's final-adjustment result; it is
// replaced by the time-model result when a kind is kept. `ba_options` the
// final adjustment's (without time model). Returns false (with `error`)
// only when a kind is on and the model cannot run (no frameset times, the
// adjustment failed); auto then logs why and keeps today's result.
bool AdjustRigWithCaptureTimeModel(const CaptureTimeModelOptions& options,
                                   const FinalBundleAdjustmentOptions&
                                       ba_options,
                                   const RigDataset& dataset,
                                   RigCalibration* calibration,
                                   CaptureTimeModel* model,
                                   std::string* error);

}  // namespace rig_calibrator
