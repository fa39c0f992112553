// The rig's motion around one frameset, for observations taken a little
// before or after the frameset's nominal time t_f (unsynchronized cameras,
// rolling shutter): the final bundle adjustment's time model
// (final_bundle_adjuster.h).
//
// Model. With world_from_rig(t) = (R(t), c(t)) the rig's trajectory and
// Q_f = rig_from_world(t_f), the rig's pose at t_f + tau is Q_f moved by the
// rig's own motion since t_f, expressed in the rig frame at t_f:
//
//   rig_from_world(t_f + tau) = M_f(tau)^-1 Q_f,
//   M_f(tau) = rig_f_from_rig(t_f + tau) = (Exp(u(tau)), p(tau)),
//   u(tau) = tau u1 + tau^2/2 u2 + tau^3/6 u3,
//   p(tau) = tau p1 + tau^2/2 p2 + tau^3/6 p3,
//
// u(tau) = Log(R_f^T R(t_f + tau)) (the rotation in the tangent space at
// R_f) and p(tau) = R_f^T (c(t_f + tau) - c_f) (the rig origin's path in the
// rig frame at t_f) to third order in tau: u1 is the body angular velocity,
// u2 its derivative (d/dt Jr(u) u' = u'' at u = 0), p1..p3 the velocity,
// acceleration and jerk of the rig origin in the rig frame at t_f. So a point
// of the world is, in the rig frame at t_f + tau,
//
//   x_rig = Exp(-u(tau)) (Q_f X - p(tau)).
//
// Why this form: the motion is relative to Q_f, so it follows Q_f while an
// adjustment moves it (held fixed within a solve, recomputed from the
// adjusted poses between solves; the velocity and acceleration are
// estimated instead, below), and each observation needs only its own
// frameset's pose, as without a time model. Why third order: the
// truncation error is tau^4/24 |u''''|; a first-order (constant twist)
// model errs by tau^2/2 |u2|, 0.04 deg at tau = 50 ms and 0.5 rad/s^2, twice
// the rotation accuracy the calibration reaches, and rolling-shutter rows
// reach tau = 80 ms. Measured on the synthetic time model's trajectory
// (capture_time_model_test.cc,
// CaptureTimeModel.ThirdOrderMotionModelErrorOnTheSyntheticTrajectory).
//
// Derivatives. At each frameset with a pose, the degree <= 4 polynomial
// through the (up to) five nearest posed framesets (the window shifted
// inward at the ends; fewer knots lower the degree) of u_j = Log(R_f^T R_j)
// and p_j = R_f^T (c_j - c_f), differentiated at t_f. Its error is O(Delta^5
// / Delta^k) for the k-th derivative, Delta the frameset interval. The final
// adjustment estimates the velocity p1 and acceleration p2 instead, with a
// prior towards these (UseTranslationDerivatives below).
//
// The frameset's own pose in that polynomial. The motion is held within a
// solve and recomputed from the adjusted poses between solves, and through
// the poses it feeds back: a change e_j of pose j moves frameset f's k-th
// derivative by w_kj e_j, so an image taken tau after t_f sees the rig moved
// by sum_j G_j(tau) e_j, G_j(tau) = sum_k w_kj tau^k / k!, on top of its own
// pose's change (w_kf taken with the own pose's sign: u_f = p_f = 0 there).
// The next solve undoes it by moving the poses the other way, and the
// alternation multiplies the poses' error by about the mean G over the
// images, which must stay well below 1. Two patterns are the worst:
//  - the own pose alone at the last frameset of the quartic through five
//    (w = 25/12 / Delta, 35/12 / Delta^2, 5/2 / Delta^3 for Delta the
//    interval): at 15 Hz 1.5 for a helmet frameset whose images are up to
//    53 ms late and without its reference camera's image; the pose ran
//    1.6 m off in two solves, took the offsets 1 ms off and left the
//    uncertainty undetermined;
//  - poses alternating from frameset to frameset, in the interior: the
//    second derivative's weights (-1/12, 4/3, -5/2, 4/3, -1/12) / Delta^2
//    add up to -16/3 / Delta^2 on it, G = -8/3 (tau / Delta)^2: at 15 Hz
//    -0.73 over a car's images (offsets in +-36 ms, 22 us/row), whose
//    offsets ended 2.6 ms off.
// Through the window's other framesets alone (the polynomial of degree <= 3
// through four), a change dc of the own position shifts every knot alike
// (p_j by -R_f^T dc) and moves no derivative, a change of its rotation only
// re-expresses the motion in the turned frame (by about |u(tau)| and
// |p(tau)| times it: centimetres against the metres to the points), and
// the alternating pattern's gain is +2/3 (tau / Delta)^2. So the interior
// framesets' motions (a window centred on the frameset) leave their own
// pose out where the alternating gain's mean over all images (the median
// interval) exceeds kMaxOwnPoseGain, and any frameset's does where its own
// gain's mean over its images does. Without the own pose the motion is
// less accurate, at the ends most (an extrapolation there: 0.005 deg and
// 23 mm at |tau| <= 80 ms on the synthetic walk at 15 Hz, against 0.0004
// deg and 2 mm; and the velocities' prior, whose width their deviations
// from p1 set, widens with it), so it is not the rule: at 5 Hz and +-50 ms
// every frameset keeps its own pose (leaving it out at the two ends took
// the ring's centre from 0.56 to 3.7 mm); at 15 Hz and +-50 ms the interior
// ones leave it out, and an end does where its images are late (or early)
// on average.
#pragma once

#include <ceres/rotation.h>

#include <Eigen/Core>

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "src/geometry/rigid3d.h"

namespace rig_calibrator {

// [u1, u2, u3, p1, p2, p3], 3 values each (see above).
using FramesetMotion = std::array<double, 18>;

// The polynomial's velocity and acceleration at a frameset as weights on
// its window's positions, [p1, p2] = sum_j [w1_j; w2_j] p_j with p_j =
// R_f^T (c_j - c_f) (above), so that the velocities' prior
// (translation_prior_cost.h) takes them as functions of the poses inside a
// solve. `window`: the kStencil = 5 nearest posed framesets (fewer when
// fewer have a pose), the frameset's own among them at `own_slot`, with
// weight zero where its motion leaves the own pose out. The window depends
// only on which framesets have a pose, so that a cost built on it keeps its
// parameter blocks while the weights change between solves. Empty window:
// a frameset without a pose.
struct TranslationStencil {
  std::vector<int> window;
  int own_slot = -1;
  Eigen::Matrix<double, 2, Eigen::Dynamic> weights;  // 2 x window size
};

// Per frameset the motion above from the rig poses of the framesets that
// have one (rig_from_world, one entry per frameset) at `times_s` (one per
// frameset, strictly increasing); zero motion for framesets without a pose.
// `without_own_pose` (per frameset, or empty: none) marks the framesets
// whose motion leaves their own pose out (see above; with fewer than three
// posed framesets it is kept). `stencils` (optional): per frameset the
// weights of its p1 and p2, written element by element (the costs point
// into them). False with `error` when sizes differ or fewer than two
// framesets have a pose.
bool ComputeFramesetMotions(
    const std::vector<double>& times_s,
    const std::vector<std::optional<Rigid3d>>& rig_from_world,
    std::vector<FramesetMotion>* motions, std::string* error,
    const std::vector<char>& without_own_pose = {},
    std::vector<TranslationStencil>* stencils = nullptr);

// The own pose's gain above beyond which a frameset's motion leaves it out:
// the alternation then shrinks the pose's error at least by half per solve
// (convergence needs |G| < 1; the margin covers the images' unequal weights
// in the solve, which the mean over images does not see).
constexpr double kMaxOwnPoseGain = 0.5;

// The framesets whose motion leaves their own pose out (above), for
// ComputeFramesetMotions' `without_own_pose`: those whose own pose's mean
// gain |G| over their images exceeds kMaxOwnPoseGain, and every interior
// one (its window centred on it) when the alternating pattern's mean gain
// 8/3 (tau / Delta)^2 over every image does. `capture_offsets_s`: per frameset, the instants of its
// images relative to t_f in seconds (time offset plus line delay times the
// middle row). None with fewer than three posed framesets.
std::vector<char> FramesetsWithoutOwnPose(
    const std::vector<double>& times_s,
    const std::vector<std::optional<Rigid3d>>& rig_from_world,
    const std::vector<std::vector<double>>& capture_offsets_s);

// With the final adjustment's time model the rig's translational velocity
// and acceleration at each frameset are estimated, not taken from the
// polynomial: at a 5 Hz frameset rate the polynomial through the frameset
// poses misses a walk's bob (its p1 off by 0.25 m/s RMS on the synthetic
// walk at 1.5 m/s, 20 mm at tau = 80 ms; p2 by 1.3 m/s^2), and at 15 Hz a
// car's 4.8 Hz vibration (1 cm, 9 m/s^2), while u1 and u2 stay within
// 0.001 rad/s and rad/s^2. [p1, p2], the layout of FramesetMotion's
// entries 9..14, so that &motion[9] is the polynomial's own.
using TranslationDerivatives = Eigen::Matrix<double, 6, 1>;

// The estimates replace p1 and p2 (`estimates`, per frameset, map units
// per second and per second squared in the rig frame at t_f; empty: none)
// for every frameset (one without a pose has zero motion, and its estimate
// stays zero).
void UseTranslationDerivatives(
    const std::vector<TranslationDerivatives>& estimates,
    std::vector<FramesetMotion>* motions);

// The prior of the estimated derivatives (translation_prior_cost.h): the
// polynomial's error d_f = e_f - [p1_f, p2_f] (e_f the estimate) as a
// Gaussian first-order autoregression from one frameset to the next,
//
//   d_f = Phi d_(f-1) + i_f,   i_f ~ N(0, S_i)   (f - 1 and f with a pose),
//   d_f ~ N(0, S_d)   (a frameset whose predecessor has none),
//
// so that the prior's residuals are W_d d_f at the first frameset of each
// run and W_i (d_f - Phi d_(f-1)) after it (W = S^-1/2), each block
// diagonal: the velocity apart from the acceleration.
//
// Why a covariance, not one scale for every axis: the error differs by
// direction. On the synthetic car at 15 Hz (velocities alone estimated)
// the velocities deviated by 0.22 m/s RMS along the rig's vertical axis
// (its vibration) and 0.02-0.04 m/s across it, and one scale for all
// three, 0.13 m/s, moved the centres by 0.64 mm RMS along the vertical
// over 8 seeds (0.55 mm with the covariance, 0.31 mm with the
// accelerations estimated too).
//
// Why from frameset to frameset: the polynomial's error is not independent
// across framesets. For a motion of frequency omega (a walk's bob, a car's
// vibration) the stencil's error is a sinusoid of the same frequency, whose
// lag-1 correlation is cos(omega Delta), negative when the framesets sample
// the motion fewer than four times a period: at the end of the adjustment
// of the synthetic helmet at 5 Hz (seed 4) -0.76 along the rig's vertical.
// The prior is what holds the velocity error common to all framesets, which
// moves each camera by its offset times it exactly as a change of its
// centre does: taken as independent it holds it to S_d^1/2 / sqrt(n) over n
// framesets, the autoregression to that times sqrt((1 + phi) / (1 - phi)),
// 2.7 times tighter at phi = -0.76. On that helmet the cameras' centres were
// 5-8.6 sigma off along the vertical (up to 2.95 mm) with the independent
// prior, and within 2 sigma (0.40 mm) with it.
//
// Estimated from the current estimates (updated between solves, an EM step
// for the prior): S_d the mean d_f d_f^T over the framesets with a pose;
// Phi = U diag(phi) U^T with U S_d's principal axes and phi_j the
// least-squares regression of u_j^T d_f on u_j^T d_(f-1) over the
// consecutive pairs (none with fewer than kMinTranslationPriorPairs), in
// [-kMaxTranslationPriorCorrelation, 0]; S_i the mean of the innovations'
// i_f i_f^T. Why not positive: the estimates are the adjustment's, which
// the prior itself smooths, and smoothing makes neighbours alike; a
// positive phi, read from them, loosens the prior of the common error, and
// the next step can read a larger one (on the helmet at 15 Hz, seed 1, the
// acceleration's phi ended at the cap, 0.9, and cam4's centre 2.2 mm, 7.6
// sigma, off, against 0.8 mm with independent deviations). A principal
// axis, not a full regression matrix: with 60 framesets the cross terms
// from an axis of small deviations onto one of large ones came out above 1
// (a singular value of 13 on the same helmet). Each principal deviation at
// least 1 % of the RMS speed (|p1|; of the RMS acceleration |p2| for the
// acceleration), so that the prior never holds the images off. Without
// estimates (`estimates` empty): the identity over the RMS speed
// (acceleration) for W_d and W_i, Phi = 0. The identity for a rig at rest.
struct TranslationPrior {
  Eigen::Matrix<double, 6, 6> whitening =  // W_d
      Eigen::Matrix<double, 6, 6>::Identity();
  Eigen::Matrix<double, 6, 6> predecessor_gain =  // Phi
      Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 6> innovation_whitening =  // W_i
      Eigen::Matrix<double, 6, 6>::Identity();
};

constexpr int kMinTranslationPriorPairs = 10;
constexpr double kMaxTranslationPriorCorrelation = 0.9;

TranslationPrior EstimateTranslationPrior(
    const std::vector<FramesetMotion>& motions,
    const std::vector<TranslationDerivatives>& estimates,
    const std::vector<std::optional<Rigid3d>>& rig_from_world);

// x_rig = Exp(-u(tau)) (Q_f X - p(tau)), with Q_f as [qw, qx, qy, qz, tx,
// ty, tz] (PoseParams) and [p1, p2] = `translation` (6 values: the
// motion's own &motion[9], or an estimate), for autodiff and for double.
template <typename T>
void WorldToRigAtOffset(const T* rig_from_world, const T* point_in_world,
                        const FramesetMotion& motion, const T* translation,
                        const T& tau, T* point_in_rig) {
  T at_frameset[3];
  ceres::QuaternionRotatePoint(rig_from_world, point_in_world, at_frameset);
  const T a1 = tau, a2 = tau * tau / 2.0, a3 = tau * tau * tau / 6.0;
  T minus_u[3];
  for (int k = 0; k < 3; ++k) {
    minus_u[k] = -(a1 * motion[k] + a2 * motion[3 + k] + a3 * motion[6 + k]);
    at_frameset[k] += rig_from_world[4 + k] -
                      (a1 * translation[k] + a2 * translation[3 + k] +
                       a3 * motion[15 + k]);
  }
  ceres::AngleAxisRotatePoint(minus_u, at_frameset, point_in_rig);
}

}  // namespace rig_calibrator
