// The motion of a synthetic rig: the profile that shapes it (MotionProfile,
// one per preset) and the continuous-time trajectory world_from_body(t) that
// the time model (unsynchronized cameras, rolling shutter;
// SyntheticRigOptions::frameset_rate_hz > 0) samples at any instant.
// Internal to the synthetic data generator.
//
// The continuous trajectory, for a time t in seconds and s = t / tau the
// position along the profile in "profile steps" (the profile's framesets):
//   heading    yaw(t)   = A_yaw sin(2 pi s / P_yaw + phi_yaw) + r_yaw s
//   pitch(t)   = A_pitch sin(2 pi s / P_pitch + phi_pitch)   (nose up > 0)
//   roll(t)    = A_roll sin(2 pi s / P_roll + phi_roll)
//   rotation   R(t) = Rz(yaw) Ry(-pitch) Rx(roll)   (body x forward, z up)
//   ground     the track heading psi(t) = r_yaw s turns steadily, the body
//              looks around it; the ground point moves at speed v along
//              psi: x = v t sinc(kappa t), y = v t sin(kappa t / 2)
//              sinc(kappa t / 2), kappa = r_yaw / tau (a circular arc, or a
//              line for r_yaw = 0)
//   height     z(t) = h + b sin(pi s + phi_bob)   (a bob every 2 steps: a
//              walker's gait, whose pace the profile sets), or
//              z(t) = h + b sin(2 pi t / T_bob + phi_bob) with a period
//              T_bob in seconds (a vehicle body bouncing on its suspension,
//              at its own frequency however fast the profile is played)
// tau is chosen so that the heading rate peaks at the requested turn rate:
// max_t yaw'(t) = (A_yaw 2 pi / P_yaw + |r_yaw|) / tau = max_turn_rate. The
// profile keeps its amplitudes (how far the rig looks around) and its
// pattern; the speed and the turn rate set how fast it is played.
//
// On a ground loop (ground_loop.h; a rendered scene's walk) the ground
// point walks the loop instead, at speed v: at arc length v t, ellipse
// parameter phi(t), and the body looks outward around phi:
//   yaw(t) = phi(t) + A_yaw sin(2 pi s / P_yaw + phi_yaw)
// (no steady turn r_yaw: the loop turns). The loop's own heading rate
// phi'(t) = v dphi/ds peaks at v / min(a, b), so tau gives the swing the
// rest: A_yaw 2 pi / P_yaw / tau = max_turn_rate - v / min(a, b).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <random>

#include "src/geometry/rigid3d.h"
#include "src/synthetic/ground_loop.h"

namespace rig_calibrator {

// How the rig moves: a walk or a drive with sinusoidal yaw, pitch and roll
// around a slowly turning heading (phases are drawn from the seed). Periods
// and rates are per frameset for the per-frameset trajectory (rig_motion.h)
// and per profile step for the continuous one (RigTrajectory).
struct MotionProfile {
  double step_m = 0.4;    // distance between framesets
  double height_m = 1.6;  // body origin above the ground
  double bob_m = 0.03;
  // T_bob above, seconds; 0: a bob every 2 profile steps.
  double bob_period_s = 0;
  double yaw_amplitude_deg = 40, yaw_period = 25, yaw_rate_deg = 3;
  double pitch_amplitude_deg = 8, pitch_period = 17;
  double roll_amplitude_deg = 6, roll_period = 13;
};

class RigTrajectory {
 public:
  // The trajectory of the profile at ground speed speed_m_s (> 0) whose
  // heading turns at up to max_turn_rate_deg_s (> 0); with rotation_only the
  // body stays at its position at t = 0. Draws the 4 phases (yaw, pitch,
  // roll, bob) from *rng, as the per-frameset trajectory does. A profile
  // without any heading change is played at its own pace, tau = step_m /
  // speed_m_s.
  RigTrajectory(const MotionProfile& motion, double speed_m_s,
                double max_turn_rate_deg_s, bool rotation_only,
                std::mt19937* rng);
  // The trajectory on `loop` (above), at height motion.height_m; needs
  // max_turn_rate_deg_s > LoopTurnRateDegS(loop, speed_m_s). Draws the same
  // 4 phases.
  RigTrajectory(const MotionProfile& motion, double speed_m_s,
                double max_turn_rate_deg_s, const GroundLoop& loop,
                std::mt19937* rng);
  // The largest heading rate of walking `loop` at speed_m_s, deg/s.
  static double LoopTurnRateDegS(const GroundLoop& loop, double speed_m_s);

  // The body pose at time t (seconds; any t, also negative).
  Rigid3d WorldFromBody(double t) const;
  // The derivative of the body origin's position at t, in the world (map
  // units per second).
  Eigen::Vector3d LinearVelocity(double t) const;
  // omega with dR/dt = [omega]x R for R = the world_from_body rotation at t:
  // the body's angular velocity in world coordinates, rad/s.
  Eigen::Vector3d AngularVelocity(double t) const;
  // Multiplies every position by `scale` (SyntheticRigOptions::map_scale):
  // the map's unit changes, the motion does not.
  void ScalePositions(double scale) { position_scale_ *= scale; }

 private:
  struct Angles {
    double yaw = 0, pitch = 0, roll = 0;  // radians
  };
  // The angles and their time derivatives (rad/s) at t.
  void AnglesAt(double t, Angles* angles, Angles* rates) const;
  // The unscaled body position at t.
  Eigen::Vector3d PositionAt(double t) const;
  // The bob's height above h at t and its rate (map units per second,
  // unscaled).
  double BobAt(double t, double* rate) const;

  MotionProfile motion_;
  std::optional<GroundLoop> loop_;
  double speed_m_s_ = 0;
  double seconds_per_step_ = 1;  // tau
  bool rotation_only_ = false;
  double position_scale_ = 1;
  double yaw_phase_ = 0, pitch_phase_ = 0, roll_phase_ = 0, bob_phase_ = 0;
};

}  // namespace rig_calibrator
