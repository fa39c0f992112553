// Capture-time offsets of unsynchronized rig cameras from the orientations
// of their images alone: the start of the capture-time model
// (capture_time_model.h), before anything about the offsets is known.
//
// Why orientations. The single-image localizations of the default method
// (1dr, initial_pose_estimation.h) have a complete rotation that depends
// neither on the intrinsics nor on synchronization (the 1D radial pose needs
// only the principal point); their translation lacks tz. Every later pose
// of an image is made with intrinsics fitted to the synchronized rig model,
// which absorb part of the rig's motion during an offset and pull offsets
// measured from them toward 0 (docs/time_model.md). The orientations do not
// have that bias.
//
// Problem. Frameset f has the nominal time t_f; camera c captures it at
// t_f + delta_c (delta_ref = 0). Its image's orientation is
//   R_{c,f} = Q_c R_ref(t_f + delta_c),
// with R_ref(t) the reference camera's (= the rig's) cam_from_world rotation
// at time t and Q_c the constant cam_from_rig rotation. So for the right
// delta the samples
//   X_f(delta) = R_{c,f} R_ref(t_f + delta)^T
// are all Q_c, and for a wrong one they differ by the rig's rotation during
// delta_c - delta, which varies with the rig's angular velocity.
//
// Method:
//  1. Reference orientations that the other cameras agree with. For camera
//     c the samples Y_f = R_{c,f} R_{ref,f}^T are Q_c up to the rig's
//     rotation during delta_c, at most w_hi search_range_s (w_hi: 1.2 times
//     the 90th percentile of the reference's chord speeds
//     angle(R_{ref,f+1} R_{ref,f}^T) / (t_{f+1} - t_f) below
//     max_angular_speed_rad_s), plus 10 b (b below). Within that tolerance
//     of the sample agreeing with most others, frameset f agrees. A
//     reference orientation is kept unless most of the cameras with an
//     orientation in its frameset disagree there.
//  2. R_ref(t): the kept orientations interpolated by PoseTrajectory
//     (pose_interpolation.h: cubic Hermite in the tangent space, C1; 0.004
//     deg off at 5 Hz on a walk turning at 65 deg/s), in pieces split where
//     consecutive knots are more than max_gap_intervals frame intervals
//     apart. Camera c's samples are the framesets with an orientation whose
//     whole window [t_f - search_range_s, t_f + search_range_s] lies in one
//     piece: the profile then uses the same framesets at every offset and
//     never extrapolates.
//  3. The profile
//       cost(delta) = min_Q (1/n) sum_f rho(angle(X_f(delta) Q^T)),
//       rho(a) = log(1 + a^2 / b^2), b = loss_scale_rad (Cauchy),
//     over camera c's n samples. The inner minimum by iteratively reweighted
//     averaging: from the sample agreeing with most others within 10 b, the
//     weighted mean (sign-aligned quaternion sum, the chordal mean for
//     rotations this close) with weights 1 / (1 + a_f^2 / b^2), 20
//     iterations.
//  4. The profile on a grid of coarse_step_s over [-search_range_s,
//     search_range_s], then golden-section search within one grid step of the
//     best point down to tolerance_s.
//  5. When the residuals at that offset are larger than the scale (median
//     angle m > b: orientations much noisier than the options assume, e.g.
//     rolling-shutter fisheye images, 0.5-0.6 deg on the rendered helmet),
//     steps 3-4 again with b = 3 m, so that the right offsets' samples are
//     inliers of the loss and the profile is not flat for lack of them.
//     (Not for m a little below b: a larger scale down-weights wrong
//     orientations less, and at 0.05 deg of noise b = 2 m doubled the
//     errors of the noisy test.)
//
// Found when n >= min_framesets, the minimum is inside the search range
// (not within one step of its bounds), and the profile at its minimum is at
// most half its value at either bound: a rig that does not turn, or turns at
// a constant rate about a fixed axis, gives a flat profile (a shift in time
// of a constant rotation rate is absorbed by Q_c), and then no offset is
// reported.
//
// Needs a trajectory: the framesets must sample one continuous motion
// densely enough for the interpolation (at 5 Hz and 65 deg/s, 13 deg between
// framesets). Framesets that are independent poses (the rendered demo's,
// docs/time_model.md) have no R_ref(t) between them.
//
// Limits. The orientation of a rolling-shutter image is about that of its
// middle row, so the offset found is about delta_c + (rho_c - rho_ref) H / 2
// (rho the line delays, H the rows; up to a few ms for 20-30 us/row): a
// start, not a measurement. Wrong orientations are down-weighted by the
// Cauchy loss, not removed. Accuracy: only the varying part of the angular
// velocity w tells offsets apart (a constant one is absorbed by Q_c), so a
// frameset's offset is known to about sigma_R / |w_f - mean w| and the
// minimum to that over sqrt(n). Measured (time_offsets_from_rotations_test.cc,
// the smooth walk at 5 Hz, 0.05 deg noise, 10 % wrong by 5-40 deg, 10 %
// missing, 60 framesets): within 0.86 ms over 30 draws; with 20 % wrong up
// to 2 ms, with 20 framesets up to 5.7 ms; exact orientations within 25 us.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

namespace rig_calibrator {

struct RotationTimeOffsetProblem {
  // t_f per frameset, seconds, strictly increasing.
  std::vector<double> frameset_times_s;
  // cam_from_world[c][f]: the rotation of camera c's image of frameset f
  // (cam_from_world), if it was localized; one entry per frameset.
  std::vector<std::vector<std::optional<Eigen::Quaterniond>>> cam_from_world;
  int reference_camera = 0;
};

struct RotationTimeOffsetOptions {
  double search_range_s = 0.1;
  double coarse_step_s = 0.001;
  double tolerance_s = 1e-6;
  // Cauchy scale b (about 2-5 times a localization's rotation noise: an
  // offset error of 5 ms at 60 deg/s turns the rig by 0.3 deg, outside the
  // loss's flat part); raised to the data's own scale by step 5.
  double loss_scale_rad = 0.2 * M_PI / 180;
  // Chord speeds above this are jumps of wrong localizations.
  double max_angular_speed_rad_s = M_PI;
  double max_gap_intervals = 2.5;
  int min_framesets = 8;
};

struct RotationTimeOffset {
  bool found = false;
  double offset_s = 0.0;  // delta_c (the best value found even if !found)
  // Q_c, the cam_from_rig rotation at offset_s (rig = reference camera).
  Eigen::Quaterniond cam_from_rig = Eigen::Quaterniond::Identity();
  int num_framesets = 0;  // n of the profile
  // Median angle(X_f Q^T) at offset_s, radians.
  double median_residual_rad = 0.0;
  std::string diagnosis;  // why not found; empty otherwise
};

// One result per camera (the reference: found, offset 0, identity). False
// with a message on bad input (sizes, times, reference index, options,
// non-finite rotations).
bool EstimateTimeOffsetsFromRotations(
    const RotationTimeOffsetProblem& problem,
    const RotationTimeOffsetOptions& options,
    std::vector<RotationTimeOffset>* offsets, std::string* error);

}  // namespace rig_calibrator
