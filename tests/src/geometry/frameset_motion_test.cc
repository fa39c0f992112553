// The frameset motion (frameset_motion.h): derivatives exact on a motion
// the quartic through five framesets represents; the estimated velocities
// replace p1 and nothing else; the velocity prior's scale over the posed
// framesets, and its residual and Jacobian (frameset_velocity_prior_cost.h).
#include "src/geometry/frameset_motion.h"

#include <gtest/gtest.h>

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
