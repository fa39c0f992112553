// The continuous trajectory of the time model: its ground speed and peak
// heading rate are the requested ones (finite differences of
// WorldFromBody), its velocities are the derivatives of its poses, and
// rotation_only and ScalePositions do what they say.
#include "src/synthetic/rig_trajectory.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "src/synthetic/rig_presets.h"

namespace rig_calibrator {
namespace rig_trajectory_test {

RigTrajectory TrajectoryOf(const MotionProfile& profile, double speed_m_s,
                           double max_turn_rate_deg_s, unsigned int seed,
                           bool rotation_only = false) {
  std::mt19937 rng(seed);
  return RigTrajectory(profile, speed_m_s, max_turn_rate_deg_s, rotation_only,
                       &rng);
}

// The heading of the body's forward axis x in the ground plane: the yaw, as
// R e_x = Rz(yaw) Ry(-pitch) e_x keeps the yaw's azimuth.
double HeadingOf(const Rigid3d& world_from_body) {
  const Eigen::Matrix3d rotation = world_from_body.RotationMatrix();
  return std::atan2(rotation(1, 0), rotation(0, 0));
}

// Wrapped to (-pi, pi].
double WrapAngle(double angle) {
  return std::remainder(angle, 2 * M_PI);
}

// Over 30 s sampled every 2 ms, by central differences (h = 0.1 ms): the
// ground speed is the requested one everywhere, the heading rate reaches the
// requested peak and never exceeds it; for every preset's profile and two
// speed/turn-rate pairs.
TEST(RigTrajectory, SpeedAndTurnRateAreAsAsked) {
  const double h = 1e-4;
  for (const RigPreset preset : AllRigPresets()) {
    for (const auto& [speed, turn_rate_deg] :
         {std::pair<double, double>{1.5, 60}, {4.0, 25}}) {
      SCOPED_TRACE(RigPresetName(preset) + " at " + std::to_string(speed) +
                   " m/s, " + std::to_string(turn_rate_deg) + " deg/s");
      const RigTrajectory trajectory = TrajectoryOf(
          MakePresetDefinition(preset, 0).motion, speed, turn_rate_deg, 3);
      double max_speed_error = 0, max_heading_rate_deg = 0;
      for (double t = 0; t < 30; t += 2e-3) {
        const Rigid3d before = trajectory.WorldFromBody(t - h);
        const Rigid3d after = trajectory.WorldFromBody(t + h);
        const double ground_speed =
            (after.translation - before.translation).head<2>().norm() /
            (2 * h);
        max_speed_error =
            std::max(max_speed_error, std::abs(ground_speed - speed));
        const double heading_rate_deg =
            WrapAngle(HeadingOf(after) - HeadingOf(before)) / (2 * h) * 180 /
            M_PI;
        max_heading_rate_deg =
            std::max(max_heading_rate_deg, std::abs(heading_rate_deg));
      }
      EXPECT_LT(max_speed_error, 1e-6 * speed);
      EXPECT_LT(max_heading_rate_deg, turn_rate_deg * (1 + 1e-6));
      EXPECT_GT(max_heading_rate_deg, turn_rate_deg * (1 - 1e-3));
    }
  }
}

// LinearVelocity and AngularVelocity are the derivatives of the position and
// of the rotation (dR/dt = [omega]x R), by central differences.
TEST(RigTrajectory, VelocitiesAreTheDerivativesOfThePoses) {
  const double h = 1e-5;
  const RigTrajectory trajectory = TrajectoryOf(
      MakePresetDefinition(RigPreset::kFisheyeHelmet5, 0).motion, 1.5, 60, 8);
  for (double t = -2; t < 10; t += 0.37) {
    const Rigid3d before = trajectory.WorldFromBody(t - h);
    const Rigid3d after = trajectory.WorldFromBody(t + h);
    const Eigen::Vector3d linear =
        (after.translation - before.translation) / (2 * h);
    EXPECT_LT((linear - trajectory.LinearVelocity(t)).norm(), 1e-6) << t;
    // R(t + h) R(t - h)^T = exp(2 h [omega]x) up to O(h^3).
    const Eigen::AngleAxisd step(after.rotation * before.rotation.inverse());
    const Eigen::Vector3d angular = step.angle() * step.axis() / (2 * h);
    EXPECT_LT((angular - trajectory.AngularVelocity(t)).norm(), 1e-6) << t;
    // The rig turns: no instant of this walk is still.
    EXPECT_GT(trajectory.AngularVelocity(t).norm(), 0.0);
  }
}

// The car's body bounces at its own 1.25 Hz (MotionProfile::bob_period_s,
// 0.8 s) whatever the turn rate that sets the profile's pace: its height
// repeats after 0.8 s, not after half of it, its vertical velocity is the
// derivative of the height, and the vertical acceleration peaks at
// b (2 pi / T)^2 = 0.62 m/s^2. A walker's bob (every 2 profile steps)
// follows the pace: at twice the turn rate it bobs twice as fast.
TEST(RigTrajectory, CarBouncesAtItsOwnFrequencyWalkerAtThePace) {
  const MotionProfile car =
      MakePresetDefinition(RigPreset::kCarSurround4, 0).motion;
  ASSERT_EQ(car.bob_period_s, 0.8);
  const double h = 1e-4;
  for (const double turn_rate_deg : {30.0, 60.0}) {
    const RigTrajectory trajectory = TrajectoryOf(car, 1.5, turn_rate_deg, 2);
    double max_acceleration = 0;
    for (double t = 0; t < 4; t += 0.013) {
      const double z = trajectory.WorldFromBody(t).translation.z();
      EXPECT_NEAR(trajectory.WorldFromBody(t + 0.8).translation.z(), z, 1e-12)
          << t;
      const double before = trajectory.WorldFromBody(t - h).translation.z();
      const double after = trajectory.WorldFromBody(t + h).translation.z();
      EXPECT_NEAR((after - before) / (2 * h), trajectory.LinearVelocity(t).z(),
                  1e-6)
          << t;
      max_acceleration = std::max(max_acceleration,
                                  std::abs(after - 2 * z + before) / (h * h));
    }
    EXPECT_NEAR(max_acceleration, car.bob_m * std::pow(2 * M_PI / 0.8, 2),
                0.01);
    // Half a period later the bob is at its opposite (z = -z about h).
    EXPECT_GT(std::abs(trajectory.WorldFromBody(0.4).translation.z() -
                       trajectory.WorldFromBody(0).translation.z()) +
                  std::abs(trajectory.WorldFromBody(0.6).translation.z() -
                           trajectory.WorldFromBody(0.2).translation.z()),
              car.bob_m);
  }
  // The walker: the bob's vertical speed peaks at b pi / tau, tau halving
  // when the turn rate doubles.
  const MotionProfile walk =
      MakePresetDefinition(RigPreset::kFisheyeHelmet5, 0).motion;
  ASSERT_EQ(walk.bob_period_s, 0);
  double peak[2] = {0, 0};
  for (int i = 0; i < 2; ++i) {
    const RigTrajectory trajectory =
        TrajectoryOf(walk, 1.5, i == 0 ? 30.0 : 60.0, 2);
    for (double t = 0; t < 4; t += 1e-3) {
      peak[i] = std::max(peak[i], std::abs(trajectory.LinearVelocity(t).z()));
    }
  }
  EXPECT_NEAR(peak[1] / peak[0], 2.0, 1e-3);
}

// On a ground loop (the rendered rig's walk, the courtyard's proportions):
// over 30 s (more than a lap) the body stays on the ellipse at its height
// plus the bob, at the requested ground speed; the heading rate never
// exceeds the requested turn rate and comes within 5 % of it; the
// velocities are the derivatives of the poses; the body looks outward
// within the swing's amplitude.
TEST(RigTrajectory, LoopWalkIsOnTheEllipseAtSpeedAndTurnRate) {
  const Eigen::Vector2d center(0.5, -1), radii(4.2, 3.9);
  const GroundLoop loop(center, radii, 1.1);
  MotionProfile profile =
      MakePresetDefinition(RigPreset::kFisheyeHelmet5, 0).motion;
  profile.height_m = 1.4;
  const double speed = 1.5, turn_rate_deg = 60;
  ASSERT_LT(RigTrajectory::LoopTurnRateDegS(loop, speed), turn_rate_deg);
  std::mt19937 rng(5);
  const RigTrajectory trajectory(profile, speed, turn_rate_deg, loop, &rng);
  const double h = 1e-4;
  double max_speed_error = 0, max_heading_rate_deg = 0, max_off_ellipse = 0;
  double max_outward_deg = 0;
  for (double t = 0; t < 30; t += 2e-3) {
    const Rigid3d pose = trajectory.WorldFromBody(t);
    const Eigen::Vector2d ground =
        (pose.translation.head<2>() - center).cwiseQuotient(radii);
    max_off_ellipse = std::max(max_off_ellipse, std::abs(ground.norm() - 1));
    EXPECT_LE(std::abs(pose.translation.z() - 1.4), profile.bob_m + 1e-12);
    const Rigid3d before = trajectory.WorldFromBody(t - h);
    const Rigid3d after = trajectory.WorldFromBody(t + h);
    max_speed_error = std::max(
        max_speed_error,
        std::abs((after.translation - before.translation).head<2>().norm() /
                     (2 * h) -
                 speed));
    max_heading_rate_deg = std::max(
        max_heading_rate_deg,
        std::abs(WrapAngle(HeadingOf(after) - HeadingOf(before)) / (2 * h)) *
            180 / M_PI);
    max_outward_deg = std::max(
        max_outward_deg,
        std::abs(WrapAngle(HeadingOf(pose) - std::atan2(ground.y(),
                                                        ground.x()))) *
            180 / M_PI);
    if (std::fmod(t, 0.37) < 2e-3) {
      const Eigen::Vector3d linear =
          (after.translation - before.translation) / (2 * h);
      EXPECT_LT((linear - trajectory.LinearVelocity(t)).norm(), 1e-6) << t;
      const Eigen::AngleAxisd step(after.rotation * before.rotation.inverse());
      EXPECT_LT((step.angle() * step.axis() / (2 * h) -
                 trajectory.AngularVelocity(t))
                    .norm(),
                1e-6)
          << t;
    }
  }
  EXPECT_LT(max_off_ellipse, 1e-12);
  EXPECT_LT(max_speed_error, 1e-6 * speed);
  EXPECT_LT(max_heading_rate_deg, turn_rate_deg * (1 + 1e-6));
  EXPECT_GT(max_heading_rate_deg, turn_rate_deg * 0.95);
  // The heading is the ellipse parameter (the angle of the ground point
  // scaled to the unit circle) plus the swing.
  EXPECT_LT(max_outward_deg, profile.yaw_amplitude_deg + 1e-9);
  EXPECT_GT(max_outward_deg, profile.yaw_amplitude_deg * 0.9);
}

// rotation_only keeps the position of t = 0; ScalePositions scales every
// position and velocity and no rotation; the same seed gives the same
// trajectory.
TEST(RigTrajectory, RotationOnlyScaleAndSeed) {
  const MotionProfile profile =
      MakePresetDefinition(RigPreset::kCarSurround4, 0).motion;
  const RigTrajectory fixed = TrajectoryOf(profile, 1.5, 60, 4, true);
  const RigTrajectory moving = TrajectoryOf(profile, 1.5, 60, 4);
  RigTrajectory scaled = moving;
  scaled.ScalePositions(1000);
  for (double t = 0; t < 5; t += 0.5) {
    EXPECT_EQ(fixed.WorldFromBody(t).translation,
              moving.WorldFromBody(0).translation);
    EXPECT_EQ(fixed.WorldFromBody(t).rotation.coeffs(),
              moving.WorldFromBody(t).rotation.coeffs());
    EXPECT_EQ(fixed.LinearVelocity(t), Eigen::Vector3d::Zero());
    EXPECT_LT((scaled.WorldFromBody(t).translation -
               1000 * moving.WorldFromBody(t).translation)
                  .norm(),
              1e-9);
    EXPECT_LT((scaled.LinearVelocity(t) - 1000 * moving.LinearVelocity(t))
                  .norm(),
              1e-9);
    EXPECT_EQ(scaled.WorldFromBody(t).rotation.coeffs(),
              moving.WorldFromBody(t).rotation.coeffs());
    EXPECT_EQ(TrajectoryOf(profile, 1.5, 60, 4).WorldFromBody(t).translation,
              moving.WorldFromBody(t).translation);
  }
  EXPECT_NE(TrajectoryOf(profile, 1.5, 60, 5).WorldFromBody(1).rotation.coeffs(),
            moving.WorldFromBody(1).rotation.coeffs());
}

}  // namespace rig_trajectory_test
}  // namespace rig_calibrator
