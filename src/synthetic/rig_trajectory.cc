#include "src/synthetic/rig_trajectory.h"

#include <colmap/util/math.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace rig_calibrator {
namespace {

// sin(u) / u, 1 at u = 0 (accurate for tiny u: sin(u) keeps its relative
// precision there).
double Sinc(double u) { return u == 0 ? 1.0 : std::sin(u) / u; }

}  // namespace

RigTrajectory::RigTrajectory(const MotionProfile& motion, double speed_m_s,
                             double max_turn_rate_deg_s, bool rotation_only,
                             std::mt19937* rng)
    : motion_(motion), speed_m_s_(speed_m_s), rotation_only_(rotation_only) {
  std::uniform_real_distribution<double> phase_distribution(0, 2 * M_PI);
  yaw_phase_ = phase_distribution(*rng);
  pitch_phase_ = phase_distribution(*rng);
  roll_phase_ = phase_distribution(*rng);
  bob_phase_ = phase_distribution(*rng);
  // The heading rate per profile step peaks where the oscillation's rate
  // adds to the steady turn: A_yaw 2 pi / P_yaw + |r_yaw| (degrees).
  const double peak_heading_deg_per_step =
      motion.yaw_amplitude_deg * 2 * M_PI / motion.yaw_period +
      std::abs(motion.yaw_rate_deg);
  seconds_per_step_ = peak_heading_deg_per_step > 0
                          ? peak_heading_deg_per_step / max_turn_rate_deg_s
                          : motion.step_m / speed_m_s;
}

RigTrajectory::RigTrajectory(const MotionProfile& motion, double speed_m_s,
                             double max_turn_rate_deg_s, const GroundLoop& loop,
                             std::mt19937* rng)
    : RigTrajectory(motion, speed_m_s, max_turn_rate_deg_s,
                    /*rotation_only=*/false, rng) {
  loop_.emplace(loop);
  motion_.yaw_rate_deg = 0;
  // The swing's peak rate A_yaw 2 pi / P_yaw per step gets what the loop
  // leaves of the turn rate (a tenth of it at least, when the caller broke
  // the precondition).
  const double swing_budget_deg_s =
      std::max(max_turn_rate_deg_s - LoopTurnRateDegS(loop, speed_m_s),
               0.1 * max_turn_rate_deg_s);
  const double swing_deg_per_step =
      motion.yaw_amplitude_deg * 2 * M_PI / motion.yaw_period;
  seconds_per_step_ = swing_deg_per_step > 0
                          ? swing_deg_per_step / swing_budget_deg_s
                          : motion.step_m / speed_m_s;
}

double RigTrajectory::LoopTurnRateDegS(const GroundLoop& loop,
                                       double speed_m_s) {
  return colmap::RadToDeg(speed_m_s * loop.MaxAngleRatePerMeter());
}

void RigTrajectory::AnglesAt(double t, Angles* angles, Angles* rates) const {
  const double s = t / seconds_per_step_;
  const double ds_dt = 1 / seconds_per_step_;
  const double yaw_frequency = 2 * M_PI / motion_.yaw_period;
  const double pitch_frequency = 2 * M_PI / motion_.pitch_period;
  const double roll_frequency = 2 * M_PI / motion_.roll_period;
  const double yaw_argument = yaw_frequency * s + yaw_phase_;
  const double pitch_argument = pitch_frequency * s + pitch_phase_;
  const double roll_argument = roll_frequency * s + roll_phase_;
  angles->yaw = colmap::DegToRad(
      motion_.yaw_amplitude_deg * std::sin(yaw_argument) +
      motion_.yaw_rate_deg * s);
  angles->pitch = colmap::DegToRad(motion_.pitch_amplitude_deg *
                                   std::sin(pitch_argument));
  angles->roll =
      colmap::DegToRad(motion_.roll_amplitude_deg * std::sin(roll_argument));
  rates->yaw = colmap::DegToRad(motion_.yaw_amplitude_deg * yaw_frequency *
                                    std::cos(yaw_argument) +
                                motion_.yaw_rate_deg) *
               ds_dt;
  rates->pitch = colmap::DegToRad(motion_.pitch_amplitude_deg *
                                  pitch_frequency * std::cos(pitch_argument)) *
                 ds_dt;
  rates->roll = colmap::DegToRad(motion_.roll_amplitude_deg * roll_frequency *
                                 std::cos(roll_argument)) *
                ds_dt;
  if (loop_) {
    double angle_rate_per_m = 0;
    angles->yaw += loop_->AngleAt(speed_m_s_ * t, &angle_rate_per_m);
    rates->yaw += speed_m_s_ * angle_rate_per_m;
  }
}

double RigTrajectory::BobAt(double t, double* rate) const {
  // The argument grows by 2 pi per T_bob, or by pi per profile step.
  if (motion_.bob_period_s > 0) {
    const double frequency = 2 * M_PI / motion_.bob_period_s;
    *rate = motion_.bob_m * frequency * std::cos(frequency * t + bob_phase_);
    return motion_.bob_m * std::sin(frequency * t + bob_phase_);
  }
  const double s = t / seconds_per_step_;
  *rate = motion_.bob_m * M_PI / seconds_per_step_ *
          std::cos(M_PI * s + bob_phase_);
  return motion_.bob_m * std::sin(M_PI * s + bob_phase_);
}

Eigen::Vector3d RigTrajectory::PositionAt(double t) const {
  const double time = rotation_only_ ? 0.0 : t;
  double bob_rate = 0;
  const double height = motion_.height_m + BobAt(time, &bob_rate);
  if (loop_) {
    double angle_rate_per_m = 0;
    const Eigen::Vector2d ground =
        loop_->PointAt(loop_->AngleAt(speed_m_s_ * time, &angle_rate_per_m));
    return Eigen::Vector3d(ground.x(), ground.y(), height);
  }
  // The track heading psi = kappa t (kappa = r_yaw / tau, rad/s); the
  // position is the integral of v (cos psi, sin psi):
  //   x = v sin(kappa t) / kappa = v t sinc(kappa t),
  //   y = v (1 - cos(kappa t)) / kappa = v t sin(kappa t / 2) sinc(kappa t / 2),
  // both exact for kappa = 0 too.
  const double kappa =
      colmap::DegToRad(motion_.yaw_rate_deg) / seconds_per_step_;
  const double half_angle = 0.5 * kappa * time;
  return Eigen::Vector3d(
      speed_m_s_ * time * Sinc(kappa * time),
      speed_m_s_ * time * std::sin(half_angle) * Sinc(half_angle), height);
}

Rigid3d RigTrajectory::WorldFromBody(double t) const {
  Angles angles, rates;
  AnglesAt(t, &angles, &rates);
  // Body y is left and z up, so a positive pitch (nose up) is a negative
  // rotation about y (as in the per-frameset trajectory).
  const Eigen::Quaterniond rotation =
      Eigen::AngleAxisd(angles.yaw, Eigen::Vector3d::UnitZ()) *
      Eigen::AngleAxisd(-angles.pitch, Eigen::Vector3d::UnitY()) *
      Eigen::AngleAxisd(angles.roll, Eigen::Vector3d::UnitX());
  return Rigid3d(rotation, position_scale_ * PositionAt(t));
}

Eigen::Vector3d RigTrajectory::LinearVelocity(double t) const {
  if (rotation_only_) return Eigen::Vector3d::Zero();
  double bob_rate = 0;
  BobAt(t, &bob_rate);
  if (loop_) {
    double angle_rate_per_m = 0;
    const double angle = loop_->AngleAt(speed_m_s_ * t, &angle_rate_per_m);
    const Eigen::Vector2d ground =
        loop_->TangentAt(angle) * speed_m_s_ * angle_rate_per_m;
    return position_scale_ * Eigen::Vector3d(ground.x(), ground.y(), bob_rate);
  }
  const double kappa =
      colmap::DegToRad(motion_.yaw_rate_deg) / seconds_per_step_;
  return position_scale_ * Eigen::Vector3d(speed_m_s_ * std::cos(kappa * t),
                                           speed_m_s_ * std::sin(kappa * t),
                                           bob_rate);
}

Eigen::Vector3d RigTrajectory::AngularVelocity(double t) const {
  Angles angles, rates;
  AnglesAt(t, &angles, &rates);
  // R = A B C with A = Rz(yaw), B = Ry(-pitch), C = Rx(roll):
  // dR/dt R^T = [yaw' z]x + A [-pitch' y]x A^T + A B [roll' x]x B^T A^T,
  // and A [w]x A^T = [A w]x.
  const Eigen::Matrix3d yaw_rotation =
      Eigen::AngleAxisd(angles.yaw, Eigen::Vector3d::UnitZ())
          .toRotationMatrix();
  const Eigen::Matrix3d pitch_rotation =
      Eigen::AngleAxisd(-angles.pitch, Eigen::Vector3d::UnitY())
          .toRotationMatrix();
  return rates.yaw * Eigen::Vector3d::UnitZ() +
         yaw_rotation * (-rates.pitch * Eigen::Vector3d::UnitY()) +
         yaw_rotation * pitch_rotation * (rates.roll * Eigen::Vector3d::UnitX());
}

}  // namespace rig_calibrator
