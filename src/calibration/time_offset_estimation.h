// Capture-time offsets of unsynchronized rig cameras, estimated from the rig
// images' own localizations in the map.
//
// Problem. Frameset f has a nominal time t_f; camera c captures it at
// t_f + delta_c (delta_ref = 0 for the reference camera, whose frame is the
// rig frame). Every image localized on its own in the map gives an observed
// cam_from_world C_{c,f} (missing or wrong for some). With the rig pose
// rig_from_world(t) a function of time,
//   C_{c,f} = cam_from_rig_c * rig_from_world(t_f + delta_c),
// so each camera's motion through time is observed directly and delta_c,
// cam_from_rig_c follow by comparing it with the reference camera's.
//
// Method.
//  1. Consistent poses. X_{c,f} = C_{c,f} C_{ref,f}^-1 equals cam_from_rig_c
//     up to the rig's motion during delta_c. Its rotation is the sample
//     agreeing with most others (within the tolerance below), averaged with
//     them; the camera centre in the rig frame is the coordinate-wise median
//     of those samples. A pair (c, f) is consistent if X_{c,f} is within
//       rotation: w_hi |delta| + 6 sqrt(2) sigma_R,
//       position: v_hi |delta| + |p_c| (rotation tolerance) + 6 sqrt(2) sigma_p,
//     of it, w_hi, v_hi the rig's high speeds (per interval between
//     consecutive framesets the median over cameras of their chord speeds,
//     then 1.2 times the 90th percentile over intervals) and sigma_R,
//     sigma_p the stated localization noise. First with |delta| = the search
//     range (offsets unknown): the poses of consistent pairs, and the
//     reference poses consistent with some camera, are trusted.
//  2. Coarse offsets without synchronization: the angular speed is the same
//     for all cameras of a rigid rig (|w_c(t)| = |w_rig(t + delta_c)|; the
//     fixed cam_from_rig rotation does not change it). Each camera's chord
//     speeds angle(R_{c,f+1} R_{c,f}^T) / (t_{f+1} - t_f), only between
//     consecutive framesets both trusted and only below a rate gate
//     (max_angular_speed_rad_s), are compared with the reference camera's,
//     interpolated at the shifted time (cubic Hermite through consecutive
//     chords):
//       cost(delta) = mean_k rho(s_c(tau_k) - s_ref(tau_k + delta)),
//       rho(x) = log(1 + x^2 / b^2), b = speed_loss_scale_rad_s,
//     on a grid of delta over the search range (coarse_step_s), refined by a
//     parabola through the best grid point and its neighbours. Without the
//     trusted poses of step 1, 20 % wrong localizations spoil about half the
//     comparisons (a wrong pose spoils two chords of its camera, and the
//     reference's interpolation uses two chords) and the minimum is lost.
//     Then step 1 again with |delta| = |coarse offset| + 5 ms: its
//     cam_from_rig starts the refinement, and a reference pose is a knot of
//     the rig trajectory only if some camera is consistent with it (with the
//     reference camera alone, all its poses are knots).
//     Limits: it needs the angular speed to vary (a rig turning at constant
//     rate, or not at all, gives a flat cost: the refinement starts at 0);
//     a periodic motion aliases offsets a period apart (keep the search range
//     below half a period); wrong localizations smaller than the rig's
//     motion over the search range (about 7 deg at 60 deg/s and 100 ms) are
//     not caught by step 1. Chords are averages over a frame interval and
//     offsets a fraction of it: at 5 Hz it lands within a few ms
//     (time_offset_estimation_test.cc measures it).
//  3. rig_from_world(t): the reference camera's knots interpolated by
//     PoseTrajectory (pose_interpolation.h), split where consecutive knots
//     are more than max_gap_intervals frame intervals apart.
//  4. Refinement per camera: robust least squares of (delta_c, cam_from_rig_c)
//     with residual, for every frameset f where camera c is localized and
//     t_f + delta_c falls on the trajectory,
//       r_{c,f} = ( Log(R_obs R_pred^T) / sigma_R ,
//                   (c_obs - c_pred) / sigma_p ),
//       R_pred = R_cr R_rw(t_f + delta_c)     (cam_from_world rotation),
//       c_pred = c_rig(t_f + delta_c) + R_wr(t_f + delta_c) p_c,
//     (R_obs, c_obs the observed rotation and camera centre, R_cr the
//     cam_from_rig rotation, p_c the camera centre in the rig frame), under a
//     Cauchy loss, delta_c bounded to the search range. sigma_R, sigma_p are
//     first the stated noise, then the residuals' own robust scales
//     (1.4826 MAD per component), and the problem is solved again.
//  5. Uncertainty: residual blocks with chi^2 (6 dof) below 22.46 (99.9 %)
//     are inliers; the scales are re-estimated on them,
//       sigma_R^2 = sum |r_R|^2 / (3 n) * 6 n / (6 n - 7)  (same for p),
//     and Cov = (J^T J)^-1 of the whitened inlier residuals with respect to
//     (rotation of cam_from_rig, p_c, delta_c). sigma(delta_c) = sqrt(Cov_77).
//     The residual's noise is the camera's plus the interpolated reference's,
//     both measured by the scales. sigma covers that noise, not the
//     interpolation's own error: on exact data of a smooth walk at 5 Hz the
//     offsets are off by 2-7 us with sigma about 1 us. With 0.05 deg / 5 mm
//     noise, 20 % wrong and 10 % missing images, |error| / sigma over 120
//     offsets had median 0.61-0.93 (0.674 expected) and at most 1 beyond 3.
//
// Observability. delta_c is identifiable only if the rig's motion is not a
// constant screw: a shift in time of a constant angular and linear velocity
// (in the rig frame) is absorbed by cam_from_rig. A camera's offset is
// reported observable when the normal equations are well conditioned,
// sigma(delta_c) <= max_observable_sigma_s, the estimate is not at the
// search range's bound and at least min_framesets framesets are inliers;
// otherwise `observable` is false and `diagnosis` says why (the offset is
// then the best value found, not a measurement).
//
// Limits. Wrong localizations smaller than the rig's motion during the
// offset pass the consistency test of step 1; as observations the Cauchy
// loss and the inlier test discount them, but a reference knot with such an
// error bends the trajectory around it. The trajectory uses the reference
// camera only, so half the residual's variance is the reference's noise.
// Knots pooled from all cameras (their offsets and cam_from_rig known after
// a first pass) were tried: sigma fell by 20 %, but the pooled trajectory
// carries the other cameras' offset errors along the very direction delta_c
// is measured in (a time shift of the samples), which the per-camera
// covariance does not model: |error| / sigma had median 0.82 and 4.4 %
// beyond 3 instead of 0.73 and 2.2 %. A joint estimate of all offsets and the
// trajectory would be needed to use them honestly.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "src/geometry/rigid3d.h"

namespace rig_calibrator {

struct TimeOffsetProblem {
  // t_f per frameset, seconds, strictly increasing.
  std::vector<double> frameset_times_s;
  // cam_from_world[c][f]: camera c's single-image localization in frameset
  // f, if any. Every camera has one entry per frameset.
  std::vector<std::vector<std::optional<Rigid3d>>> cam_from_world;
  int reference_camera = 0;
};

struct TimeOffsetOptions {
  // Offsets are searched in [-search_range_s, search_range_s].
  double search_range_s = 0.1;
  // Grid step of the coarse search (then refined by a parabola).
  double coarse_step_s = 0.001;
  // Chord speeds above this are jumps of wrong localizations.
  double max_angular_speed_rad_s = M_PI;
  // Cauchy scale b of the speed comparison (about 1 deg/s: a few times the
  // chord speeds' noise at 5 Hz with 0.05 deg localizations, small enough
  // that an offset error of a few ms is not within the loss's flat part).
  double speed_loss_scale_rad_s = 0.02;
  // Expected localization noise (per axis): the first weights, and the
  // noise part of the consistency tolerance of step 1.
  double rotation_noise_rad = 1e-3;
  double position_noise = 0.01;  // map units
  // The trajectory is not interpolated across longer gaps.
  double max_gap_intervals = 2.5;
  // Fewer framesets than this (in the problem, with a reference pose, or as
  // a camera's inliers) cannot give an offset.
  int min_framesets = 10;
  double max_observable_sigma_s = 0.005;
};

struct CameraTimeOffset {
  double offset_s = 0.0;         // delta_c
  double offset_sigma_s = 0.0;   // infinity when the normal equations are
                                 // singular
  double coarse_offset_s = 0.0;  // step 2's estimate
  Rigid3d cam_from_rig;
  int num_framesets_used = 0;    // inlier framesets of the refinement
  bool observable = false;
  // The residual scales the uncertainty uses (radians, map units).
  double rotation_residual_rad = 0.0;
  double position_residual = 0.0;
  std::string diagnosis;  // why not observable; empty otherwise
};

// One result per camera (the reference camera: offset 0, identity, the
// number of its trajectory knots). False with a message naming the problem
// on bad input (sizes, times, reference index, non-finite poses, options) or
// when fewer than min_framesets framesets have a reference pose.
bool EstimateTimeOffsets(const TimeOffsetProblem& problem,
                         const TimeOffsetOptions& options,
                         std::vector<CameraTimeOffset>* offsets,
                         std::string* error);

}  // namespace rig_calibrator
