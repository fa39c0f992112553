// The frameset motion (frameset_motion.h): derivatives exact on a motion
// the quartic through five framesets represents, and on a cubic path
// without the frameset's own pose, which then does not move its motion; the
// framesets that leave their own pose out; the estimated velocities replace
// p1 and nothing else; the velocity prior's scale over the posed framesets,
// and its residual and Jacobian (frameset_velocity_prior_cost.h).
#include "src/geometry/frameset_motion.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "src/geometry/frameset_velocity_prior_cost.h"
#include "src/geometry/pose_interpolation.h"

namespace rig_calibrator {
namespace frameset_motion_test {

// A rig turning at a constant 0.8 rad/s about a fixed axis (u(tau) = w tau
// in the rig frame, exactly) while its origin follows a cubic in time.
Rigid3d WorldFromRigAt(double t) {
  const Eigen::Vector3d omega = 0.8 * Eigen::Vector3d(1, -2, 0.5).normalized();
  const Eigen::Vector3d centre(1.5 * t + 0.3 * t * t - 0.2 * t * t * t,
                               -0.4 * t * t, 0.1 + 0.05 * t * t * t);
  return Rigid3d(Eigen::Quaterniond(ExpSO3(omega * t)), centre);
}

std::vector<double> Times() {
  std::vector<double> times;
  for (int f = 0; f < 9; ++f) times.push_back(0.2 * f + 0.01 * (f % 3));
  return times;
}

TEST(FramesetMotion, ExactForAFixedAxisTurnAndACubicPath) {
  const std::vector<double> times = Times();
  std::vector<std::optional<Rigid3d>> poses;
  for (const double t : times) poses.push_back(WorldFromRigAt(t).Inverse());
  std::vector<FramesetMotion> motions;
  std::string error;
  ASSERT_TRUE(ComputeFramesetMotions(times, poses, &motions, &error)) << error;
  const Eigen::Vector3d omega = 0.8 * Eigen::Vector3d(1, -2, 0.5).normalized();
  for (size_t f = 0; f < times.size(); ++f) {
    const double t = times[f];
    const Eigen::Matrix3d rotation_t =
        WorldFromRigAt(t).RotationMatrix().transpose();
    // The rig-frame derivatives of the centre at t.
    const Eigen::Vector3d velocity =
        rotation_t * Eigen::Vector3d(1.5 + 0.6 * t - 0.6 * t * t, -0.8 * t,
                                     0.15 * t * t);
    const Eigen::Vector3d acceleration =
        rotation_t * Eigen::Vector3d(0.6 - 1.2 * t, -0.8, 0.3 * t);
    const Eigen::Vector3d jerk = rotation_t * Eigen::Vector3d(-1.2, 0, 0.3);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(motions[f][k], omega(k), 1e-8) << f;
      EXPECT_NEAR(motions[f][3 + k], 0, 1e-7) << f;
      EXPECT_NEAR(motions[f][6 + k], 0, 1e-6) << f;
      EXPECT_NEAR(motions[f][9 + k], velocity(k), 1e-8) << f;
      EXPECT_NEAR(motions[f][12 + k], acceleration(k), 1e-7) << f;
      EXPECT_NEAR(motions[f][15 + k], jerk(k), 1e-6) << f;
    }
  }
}

// Without the own pose (every frameset), the polynomial through the other
// four: still exact for the fixed-axis turn and the cubic path. A change of
// a frameset's own position (1e-3 map units per axis) shifts every knot
// alike and leaves its motion unchanged (to rounding), where with the own
// pose it moves the velocity by the own weight (at the last frameset
// 25/12 / Delta times 1e-3, about 0.01). A change of its rotation (1e-3
// rad per axis) only re-expresses the motion in the turned frame: u1-u3
// move by less than a fifth of what the own pose's weight moves them.
TEST(FramesetMotion, WithoutOwnPoseExactAndUnmovedByIt) {
  const std::vector<double> times = Times();
  std::vector<std::optional<Rigid3d>> poses;
  for (const double t : times) poses.push_back(WorldFromRigAt(t).Inverse());
  const std::vector<char> all(times.size(), 1);
  std::vector<FramesetMotion> motions, with_own;
  std::string error;
  ASSERT_TRUE(ComputeFramesetMotions(times, poses, &motions, &error, all))
      << error;
  ASSERT_TRUE(ComputeFramesetMotions(times, poses, &with_own, &error));
  for (size_t f = 0; f < times.size(); ++f) {
    for (int k = 0; k < 18; ++k) {
      // Exact up to the rounding of extrapolated cubics (jerk at the ends).
      EXPECT_NEAR(motions[f][k], with_own[f][k], k % 9 >= 6 ? 1e-5 : 1e-7)
          << f << " " << k;
    }
  }
  const Eigen::Vector3d change(1e-3, -1e-3, 1e-3);
  // The largest change of motion entries [first, last) at frameset f when
  // its pose is `moved` instead, without and with its own pose.
  const auto changes = [&](size_t f, const Rigid3d& moved_world_from_rig,
                           int first, int last) {
    std::vector<std::optional<Rigid3d>> moved = poses;
    moved[f] = moved_world_from_rig.Inverse();
    std::vector<FramesetMotion> without_motions, with_motions;
    EXPECT_TRUE(
        ComputeFramesetMotions(times, moved, &without_motions, &error, all));
    EXPECT_TRUE(ComputeFramesetMotions(times, moved, &with_motions, &error));
    std::pair<double, double> largest(0, 0);
    for (int k = first; k < last; ++k) {
      largest.first = std::max(
          largest.first, std::abs(without_motions[f][k] - motions[f][k]));
      largest.second = std::max(
          largest.second, std::abs(with_motions[f][k] - with_own[f][k]));
    }
    return largest;
  };
  for (const size_t f : {size_t{0}, size_t{4}, times.size() - 1}) {
    const Rigid3d world_from_rig = poses[f]->Inverse();
    const auto [position_without, position_with] =
        changes(f,
                Rigid3d(world_from_rig.rotation,
                        world_from_rig.translation + change),
                9, 18);
    EXPECT_LT(position_without, 1e-9) << f;
    EXPECT_GT(position_with, 1e-3) << f;
    const auto [rotation_without, rotation_with] = changes(
        f,
        Rigid3d(world_from_rig.rotation * Eigen::Quaterniond(ExpSO3(change)),
                world_from_rig.translation),
        0, 9);
    EXPECT_LT(rotation_without, 0.2 * rotation_with) << f;
  }
}

// Which framesets leave their own pose out. At 10 Hz, images at the
// frameset's instant except at the last frameset, whose images are 50 ms
// late (its own gain 25/12 * 0.5 + 35/12 * 0.125 + 5/2 * 0.02, about 1.5):
// that one alone. With images at 0 and +-50 ms at 15 Hz (the alternating
// pattern's gain 8/3 * 0.375 = 1): the interior framesets, whose windows
// are centred on them, and the first and last (own gain (2.56 - 0.92 + 0)
// / 3, about 0.55), not the second and the second-to-last (about -0.31).
// At 5 Hz with the same offsets: none (the last frameset's own gain about
// 0.05, the alternating 0.11).
TEST(FramesetMotion, FramesetsWithoutOwnPoseByTheirGain) {
  const auto evenly = [](double rate_hz) {
    std::vector<double> times;
    for (int f = 0; f < 12; ++f) times.push_back(f / rate_hz);
    return times;
  };
  const std::vector<std::optional<Rigid3d>> poses(12, Rigid3d());
  std::vector<std::vector<double>> offsets(12, {0, 0, 0});
  offsets.back() = {0.05, 0.05, 0.05};
  std::vector<char> expected(12, 0);
  expected.back() = 1;
  EXPECT_EQ(FramesetsWithoutOwnPose(evenly(10), poses, offsets), expected);
  offsets.assign(12, {0.0, 0.05, -0.05});
  expected.assign(12, 1);
  expected[1] = expected[10] = 0;
  EXPECT_EQ(FramesetsWithoutOwnPose(evenly(15), poses, offsets), expected);
  EXPECT_EQ(FramesetsWithoutOwnPose(evenly(5), poses, offsets),
            std::vector<char>(12, 0));
  // A frameset without a pose is never marked, nor is any with fewer than
  // three posed framesets.
  std::vector<std::optional<Rigid3d>> some = poses;
  some[3].reset();
  EXPECT_EQ(FramesetsWithoutOwnPose(evenly(15), some, offsets)[3], 0);
  std::vector<std::optional<Rigid3d>> two(12);
  two[0] = Rigid3d();
  two[5] = Rigid3d();
  EXPECT_EQ(FramesetsWithoutOwnPose(evenly(15), two, offsets),
            std::vector<char>(12, 0));
}

TEST(FramesetMotion, EstimatedVelocitiesReplaceP1Only) {
  std::vector<FramesetMotion> motions(2);
  for (int k = 0; k < 18; ++k) {
    motions[0][k] = k;
    motions[1][k] = -k;
  }
  const std::vector<FramesetMotion> before = motions;
  UseFramesetVelocities({}, &motions);  // none: unchanged
  EXPECT_EQ(motions, before);
  UseFramesetVelocities({Eigen::Vector3d(7, 8, 9), Eigen::Vector3d(1, 2, 3)},
                        &motions);
  for (int k = 0; k < 18; ++k) {
    const bool p1 = k >= 9 && k < 12;
    EXPECT_EQ(motions[0][k], p1 ? 7.0 + (k - 9) : before[0][k]) << k;
    EXPECT_EQ(motions[1][k], p1 ? 1.0 + (k - 9) : before[1][k]) << k;
  }
}

// The prior's scale: the RMS speed before any estimate, then the RMS
// deviation per axis from p1, at least 1 % of the RMS speed; over the
// framesets with a pose.
TEST(FramesetMotion, VelocityPriorSigmaOverThePosedFramesets) {
  std::vector<FramesetMotion> motions(3);
  motions[0][9] = 3;   // |p1| = 5
  motions[0][10] = 4;
  motions[1][11] = 100;  // no pose: left out
  motions[2][9] = 1;     // |p1| = 1
  const std::vector<std::optional<Rigid3d>> poses = {Rigid3d(), std::nullopt,
                                                     Rigid3d()};
  EXPECT_DOUBLE_EQ(FramesetVelocityPriorSigma(motions, {}, poses),
                   std::sqrt(13.0));
  // Deviations |(0, 0, 3)| and |(0, 0, 0)|; frameset 1's is left out.
  const std::vector<Eigen::Vector3d> velocities = {
      Eigen::Vector3d(3, 4, 3), Eigen::Vector3d(50, 0, 0),
      Eigen::Vector3d(1, 0, 0)};
  EXPECT_DOUBLE_EQ(FramesetVelocityPriorSigma(motions, velocities, poses),
                   std::sqrt(9.0 / 6));
  // No deviation: 1 % of the RMS speed.
  const std::vector<Eigen::Vector3d> on_p1 = {
      Eigen::Vector3d(3, 4, 0), Eigen::Vector3d::Zero(),
      Eigen::Vector3d(1, 0, 0)};
  EXPECT_DOUBLE_EQ(FramesetVelocityPriorSigma(motions, on_p1, poses),
                   0.01 * std::sqrt(13.0));
  // At rest, or no pose: 1.
  EXPECT_EQ(FramesetVelocityPriorSigma(std::vector<FramesetMotion>(3), {},
                                       poses),
            1.0);
  EXPECT_EQ(FramesetVelocityPriorSigma(
                motions, {}, {std::nullopt, std::nullopt, std::nullopt}),
            1.0);
}

TEST(FramesetVelocityPriorCost, ResidualAndJacobianPerAxisPair) {
  FramesetMotion motion{};
  motion[9] = 1.5;
  motion[10] = -0.2;
  motion[11] = 0.4;
  double sigma = 2.0;
  const double velocity[3] = {1.9, 0.6, -0.6};
  const double* parameters[] = {velocity};
  const FramesetVelocityPriorCost first(&motion, &sigma, 0);
  const FramesetVelocityPriorCost last(&motion, &sigma, 2);
  double residuals[2], jacobian[6];
  double* jacobians[] = {jacobian};
  ASSERT_TRUE(first.Evaluate(parameters, residuals, jacobians));
  EXPECT_NEAR(residuals[0], 0.2, 1e-15);
  EXPECT_NEAR(residuals[1], 0.4, 1e-15);
  EXPECT_EQ(std::vector<double>(jacobian, jacobian + 6),
            std::vector<double>({0.5, 0, 0, 0, 0.5, 0}));
  ASSERT_TRUE(last.Evaluate(parameters, residuals, jacobians));
  EXPECT_NEAR(residuals[0], -0.5, 1e-15);
  EXPECT_EQ(residuals[1], 0.0);
  EXPECT_EQ(std::vector<double>(jacobian, jacobian + 6),
            std::vector<double>({0, 0, 0.5, 0, 0, 0}));
  // p1 and sigma are read at every evaluation.
  motion[11] = -0.6;
  sigma = 0.5;
  ASSERT_TRUE(last.Evaluate(parameters, residuals, nullptr));
  EXPECT_NEAR(residuals[0], 0.0, 1e-15);
}

}  // namespace frameset_motion_test
}  // namespace rig_calibrator
