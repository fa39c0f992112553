// The frameset motion (frameset_motion.h): derivatives exact on a motion
// the quartic through five framesets represents, and on a cubic path
// without the frameset's own pose, which then does not move its motion; the
// framesets that leave their own pose out; the estimated velocities and
// accelerations replace p1 and p2 and nothing else; their prior over the
// posed framesets (its whitening, and its autoregression from frameset to
// frameset recovered exactly, statistically and capped), and its costs'
// stencils and residuals and Jacobians over the poses of their windows
// (translation_prior_cost.h).
#include "src/geometry/frameset_motion.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "src/geometry/pose_interpolation.h"
#include "src/geometry/translation_prior_cost.h"

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

TEST(FramesetMotion, EstimatedDerivativesReplaceP1AndP2Only) {
  std::vector<FramesetMotion> motions(2);
  for (int k = 0; k < 18; ++k) {
    motions[0][k] = k;
    motions[1][k] = -k;
  }
  const std::vector<FramesetMotion> before = motions;
  UseTranslationDerivatives({}, &motions);  // none: unchanged
  EXPECT_EQ(motions, before);
  std::vector<TranslationDerivatives> estimates(2);
  estimates[0] << 7, 8, 9, 10, 11, 12;
  estimates[1] << 1, 2, 3, 4, 5, 6;
  UseTranslationDerivatives(estimates, &motions);
  for (int k = 0; k < 18; ++k) {
    const bool estimated = k >= 9 && k < 15;
    EXPECT_EQ(motions[0][k], estimated ? 7.0 + (k - 9) : before[0][k]) << k;
    EXPECT_EQ(motions[1][k], estimated ? 1.0 + (k - 9) : before[1][k]) << k;
  }
}

// The prior's whitening, per derivative (velocity, acceleration): the RMS
// of the polynomial's before any estimate, then the covariance of the
// deviations from it to the power -1/2, each principal deviation at least
// 1 % of that RMS; over the framesets with a pose; nothing between the two.
// Fewer than kMinTranslationPriorPairs consecutive pairs: no autoregression,
// the innovations' whitening is the deviations'.
TEST(FramesetMotion, TranslationPriorWhiteningOverThePosedFramesets) {
  std::vector<FramesetMotion> motions(4);
  motions[0][9] = 3;  // |p1| = 5
  motions[0][10] = 4;
  motions[1][11] = 100;  // no pose: left out
  motions[2][9] = 1;     // |p1| = 1
  motions[3][9] = 1;     // |p1| = 1
  motions[0][14] = 2;    // |p2| = 2, 0, 0
  const std::vector<std::optional<Rigid3d>> poses = {
      Rigid3d(), std::nullopt, Rigid3d(), Rigid3d()};
  const double speed = std::sqrt(27.0 / 3);  // RMS of 5, 1, 1
  const double acceleration = std::sqrt(4.0 / 3);
  Eigen::Matrix<double, 6, 6> expected = Eigen::Matrix<double, 6, 6>::Zero();
  expected.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() / speed;
  expected.bottomRightCorner<3, 3>() =
      Eigen::Matrix3d::Identity() / acceleration;
  const TranslationPrior before = EstimateTranslationPrior(motions, {}, poses);
  EXPECT_TRUE(before.whitening.isApprox(expected, 1e-15));
  EXPECT_TRUE(before.innovation_whitening.isApprox(expected, 1e-15));
  EXPECT_TRUE(before.predecessor_gain.isZero(0));
  // Velocity deviations (0, 3, 3), (0, -3, -3), (0.3, 0, 0): the covariance
  // has (18 + 18) / 3 = 12 along (0, 1, 1) / sqrt 2 and 0.09 / 3 = 0.03
  // along x; the third direction, (0, 1, -1) / sqrt 2, none, so 1 % of the
  // speed. Acceleration deviations (0, 0, 0.6), 0, 0: 0.12 along z, the
  // floor, 1 % of the RMS acceleration, across it.
  std::vector<TranslationDerivatives> estimates(4);
  estimates[0] << 3, 7, 3, 0, 0, 2.6;
  estimates[1] << 50, 0, 0, 0, 0, 0;
  estimates[2] << 1, -3, -3, 0, 0, 0;
  estimates[3] << 1.3, 0, 0, 0, 0, 0;
  const TranslationPrior prior =
      EstimateTranslationPrior(motions, estimates, poses);
  EXPECT_TRUE(prior.predecessor_gain.isZero(0));
  EXPECT_EQ(prior.innovation_whitening, prior.whitening);
  const Eigen::Matrix<double, 6, 6>& whitening = prior.whitening;
  EXPECT_TRUE(whitening.isApprox(whitening.transpose(), 1e-12));
  EXPECT_TRUE((whitening.topRightCorner<3, 3>().isZero(0)));
  EXPECT_TRUE((whitening.bottomLeftCorner<3, 3>().isZero(0)));
  const Eigen::Matrix3d velocity_whitening = whitening.topLeftCorner<3, 3>();
  const Eigen::Vector3d along = Eigen::Vector3d(0, 1, 1) / std::sqrt(2.0);
  const Eigen::Vector3d across = Eigen::Vector3d(0, 1, -1) / std::sqrt(2.0);
  EXPECT_NEAR((velocity_whitening * along).norm(), 1 / std::sqrt(12.0),
              1e-12);
  EXPECT_NEAR((velocity_whitening * Eigen::Vector3d::UnitX()).norm(),
              1 / std::sqrt(0.03), 1e-9);
  EXPECT_NEAR((velocity_whitening * across).norm(), 1 / (0.01 * speed), 1e-9);
  EXPECT_NEAR(along.dot(velocity_whitening * Eigen::Vector3d::UnitX()), 0,
              1e-12);
  const Eigen::Matrix3d acceleration_whitening =
      whitening.bottomRightCorner<3, 3>();
  EXPECT_NEAR((acceleration_whitening * Eigen::Vector3d::UnitZ()).norm(),
              1 / std::sqrt(0.12), 1e-9);
  EXPECT_NEAR((acceleration_whitening * Eigen::Vector3d::UnitX()).norm(),
              1 / (0.01 * acceleration), 1e-7);
  // The whitened deviations have the identity as their covariance in the
  // directions above the floor: sum (W d)(W d)^T / n = I there.
  Eigen::Matrix<double, 6, 6> whitened = Eigen::Matrix<double, 6, 6>::Zero();
  for (const int f : {0, 2, 3}) {
    const TranslationDerivatives deviation =
        whitening * (estimates[f] - Eigen::Map<const TranslationDerivatives>(
                                        &motions[f][9]));
    whitened += deviation * deviation.transpose() / 3;
  }
  const Eigen::Matrix3d velocity_whitened = whitened.topLeftCorner<3, 3>();
  EXPECT_NEAR(along.dot(velocity_whitened * along), 1, 1e-12);
  EXPECT_NEAR(velocity_whitened(0, 0), 1, 1e-12);
  EXPECT_NEAR(across.dot(velocity_whitened * across), 0, 1e-12);
  EXPECT_NEAR(whitened(5, 5), 1, 1e-12);
  // No deviation: 1 % of the RMS in every direction.
  std::vector<TranslationDerivatives> on_polynomial;
  for (const FramesetMotion& motion : motions) {
    on_polynomial.push_back(
        Eigen::Map<const TranslationDerivatives>(&motion[9]));
  }
  EXPECT_TRUE(EstimateTranslationPrior(motions, on_polynomial, poses)
                  .whitening.isApprox(expected / 0.01, 1e-12));
  // At rest, or no pose: the identity.
  EXPECT_EQ(EstimateTranslationPrior(std::vector<FramesetMotion>(4), {}, poses)
                .whitening,
            (Eigen::Matrix<double, 6, 6>::Identity()));
  EXPECT_EQ(EstimateTranslationPrior(
                motions, {},
                {std::nullopt, std::nullopt, std::nullopt, std::nullopt})
                .whitening,
            (Eigen::Matrix<double, 6, 6>::Identity()));
}

// Framesets with p1 = (1e-3, 0, 0) and p2 = (0, 1e-3, 0), so that the
// floors, 1e-5 per axis, are far below the deviations, and the estimates
// [p1, p2] + deviation.
struct Autoregression {
  std::vector<FramesetMotion> motions;
  std::vector<TranslationDerivatives> estimates;
  std::vector<std::optional<Rigid3d>> poses;
};

Autoregression FromDeviations(
    const std::vector<TranslationDerivatives>& deviations) {
  Autoregression data;
  data.motions.assign(deviations.size(), FramesetMotion{});
  data.poses.assign(deviations.size(), Rigid3d());
  for (size_t f = 0; f < deviations.size(); ++f) {
    data.motions[f][9] = 1e-3;
    data.motions[f][13] = 1e-3;
    data.estimates.push_back(
        Eigen::Map<const TranslationDerivatives>(&data.motions[f][9]) +
        deviations[f]);
  }
  return data;
}

// Without innovations, exactly: three runs of 15 framesets (the frameset
// between two runs without a pose), the velocity's deviation along x in
// the first decaying as (-0.6)^f, along y in the second as (-0.3)^f, along
// z in the third as 0.5^f, so that S_d is diagonal and the regression along
// each axis exact (to the floor's bias, 4e-10 / sum d^2); the acceleration's
// along z throughout as (-0.95)^f. Phi: -0.6 and -0.3 recovered, 0.5 cut to
// 0, -0.95 capped at -kMaxTranslationPriorCorrelation; the innovations
// zero on x and y (the floor), d_f itself on the velocity's z, and
// d_f + 0.9 d_(f-1) = -0.05 d_(f-1) on the acceleration's.
TEST(FramesetMotion, TranslationPriorAutoregressionExactWithoutInnovations) {
  std::vector<TranslationDerivatives> deviations(47,
                                                 TranslationDerivatives::Zero());
  const std::array<double, 3> gains = {-0.6, -0.3, 0.5};
  for (int run = 0; run < 3; ++run) {
    for (int step = 0; step < 15; ++step) {
      deviations[16 * run + step](run) = 0.8 * std::pow(gains[run], step);
    }
  }
  for (int f = 0; f < 47; ++f) deviations[f](5) = 0.4 * std::pow(-0.95, f);
  Autoregression data = FromDeviations(deviations);
  data.poses[15] = data.poses[31] = std::nullopt;
  const TranslationPrior prior =
      EstimateTranslationPrior(data.motions, data.estimates, data.poses);
  Eigen::Matrix<double, 6, 6> expected_gain =
      Eigen::Matrix<double, 6, 6>::Zero();
  expected_gain(0, 0) = -0.6;
  expected_gain(1, 1) = -0.3;
  expected_gain(5, 5) = -kMaxTranslationPriorCorrelation;
  EXPECT_LT((prior.predecessor_gain - expected_gain).cwiseAbs().maxCoeff(),
            1e-8)
      << prior.predecessor_gain;
  // The innovations' variances, over the 42 consecutive pairs.
  double velocity_z = 0, acceleration_z = 0;
  for (int f = 1; f < 47; ++f) {
    if (!data.poses[f] || !data.poses[f - 1]) continue;
    velocity_z += deviations[f](2) * deviations[f](2) / 42;
    acceleration_z += 0.05 * deviations[f - 1](5) * 0.05 *
                      deviations[f - 1](5) / 42;
  }
  Eigen::Matrix<double, 6, 1> expected_scale;
  expected_scale << 1e-5, 1e-5, std::sqrt(velocity_z), 1e-5, 1e-5,
      std::sqrt(acceleration_z);
  EXPECT_TRUE(prior.innovation_whitening.isApprox(
      Eigen::Matrix<double, 6, 6>(expected_scale.cwiseInverse().asDiagonal()),
      1e-6))
      << prior.innovation_whitening;
}

// Deviations d_f = Phi d_(f-1) + i_f over 2000 framesets, Phi = diag(-0.76,
// -0.3, 0.5) on the velocity, innovations of 0.1, 0.05, 0.2 (so that the
// principal axes are x, y, z); diag(0.3, -0.2, -0.97) on the acceleration,
// innovations 0.1, 0.05, 0.1. Phi within its sampling error (about 1 / sqrt(2000) =
// 0.02), the positive gains cut to 0, -0.97 capped; the innovations'
// deviations within theirs.
TEST(FramesetMotion, TranslationPriorAutoregressionFromNoisyDeviations) {
  const Eigen::Array<double, 6, 1> gain =
      (Eigen::Array<double, 6, 1>() << -0.76, -0.3, 0.5, 0.3, -0.2, -0.97)
          .finished();
  const Eigen::Array<double, 6, 1> scale =
      (Eigen::Array<double, 6, 1>() << 0.1, 0.05, 0.2, 0.1, 0.05, 0.1)
          .finished();
  std::mt19937 random(7);
  std::normal_distribution<double> normal;
  std::vector<TranslationDerivatives> deviations;
  TranslationDerivatives deviation = TranslationDerivatives::Zero();
  for (int f = 0; f < 2000; ++f) {
    for (int k = 0; k < 6; ++k) {
      deviation(k) = gain(k) * deviation(k) + scale(k) * normal(random);
    }
    deviations.push_back(deviation);
  }
  const Autoregression data = FromDeviations(deviations);
  const TranslationPrior prior =
      EstimateTranslationPrior(data.motions, data.estimates, data.poses);
  const Eigen::Matrix<double, 6, 6>& phi = prior.predecessor_gain;
  EXPECT_NEAR(phi(0, 0), -0.76, 0.05);
  EXPECT_NEAR(phi(1, 1), -0.3, 0.05);
  EXPECT_NEAR(phi(2, 2), 0, 0.02);
  EXPECT_NEAR(phi(3, 3), 0, 0.02);
  EXPECT_NEAR(phi(4, 4), -0.2, 0.05);
  EXPECT_NEAR(phi(5, 5), -kMaxTranslationPriorCorrelation, 0.01);
  EXPECT_TRUE((phi.topRightCorner<3, 3>().isZero(0)));
  EXPECT_TRUE((phi.bottomLeftCorner<3, 3>().isZero(0)));
  EXPECT_LT(std::abs(phi(0, 1)) + std::abs(phi(0, 2)) + std::abs(phi(1, 2)),
            0.05);
  // The innovations: the drawn ones where the gain is kept, d_f itself on
  // the velocity's z (its stationary deviation 0.2 / sqrt(1 - 0.25) =
  // 0.231), d_f + 0.9 d_(f-1) = -0.07 d_(f-1) + i_f on the acceleration's
  // z (sqrt(0.01 + 0.07^2 0.01 / (1 - 0.97^2)) = 0.104).
  const Eigen::Matrix<double, 6, 6> covariance =
      (prior.innovation_whitening * prior.innovation_whitening).inverse();
  EXPECT_NEAR(std::sqrt(covariance(0, 0)), 0.1, 0.006);
  EXPECT_NEAR(std::sqrt(covariance(1, 1)), 0.05, 0.003);
  EXPECT_NEAR(std::sqrt(covariance(2, 2)), 0.231, 0.015);
  EXPECT_NEAR(std::sqrt(covariance(5, 5)), 0.104, 0.006);
  // The deviations' own: the alternating axis's stationary deviation,
  // 0.1 / sqrt(1 - 0.76^2) = 0.154.
  const Eigen::Matrix<double, 6, 6> deviation_covariance =
      (prior.whitening * prior.whitening).inverse();
  EXPECT_NEAR(std::sqrt(deviation_covariance(0, 0)), 0.154, 0.015);
}

// Nine framesets of the turn and cubic path above, frameset 2 without a
// pose, frameset 5's motion without its own pose: the motions, their
// stencils and the poses as the adjustment's parameters.
struct StencilCase {
  std::vector<double> times = Times();
  std::vector<std::optional<Rigid3d>> poses;
  std::vector<char> without_own_pose;
  std::vector<FramesetMotion> motions;
  std::vector<TranslationStencil> stencils;
  std::vector<PoseParams> pose_params;
  std::vector<double*> rig_poses;

  StencilCase() {
    without_own_pose.assign(times.size(), 0);
    without_own_pose[5] = 1;
    for (size_t f = 0; f < times.size(); ++f) {
      if (f != 2) poses.push_back(WorldFromRigAt(times[f]).Inverse());
      if (f == 2) poses.emplace_back();
      pose_params.push_back(f == 2 ? PoseParams{} : ToPoseParams(*poses[f]));
    }
    for (size_t f = 0; f < times.size(); ++f) {
      rig_poses.push_back(f == 2 ? nullptr : pose_params[f].data());
    }
    std::string error;
    EXPECT_TRUE(ComputeFramesetMotions(times, poses, &motions, &error,
                                       without_own_pose, &stencils))
        << error;
  }
  TranslationDerivatives Polynomial(int f) const {
    return Eigen::Map<const TranslationDerivatives>(&motions[f][9]);
  }
};

// The stencil's weights on p_j = R_f^T (c_j - c_f) give the motion's p1 and
// p2 (to rounding), from Rigid3d and from the poses' parameters
// (PolynomialTranslation); its window is the five nearest posed framesets,
// shifted inward at the ends, with a zero weight on the own pose where the
// motion leaves it out, and empty without a pose.
TEST(FramesetMotion, TranslationStencilGivesThePolynomialsP1AndP2) {
  const StencilCase data;
  ASSERT_EQ(data.stencils.size(), data.times.size());
  EXPECT_TRUE(data.stencils[2].window.empty());
  EXPECT_EQ(data.stencils[0].window, std::vector<int>({0, 1, 3, 4, 5}));
  EXPECT_EQ(data.stencils[0].own_slot, 0);
  EXPECT_EQ(data.stencils[5].window, std::vector<int>({3, 4, 5, 6, 7}));
  EXPECT_EQ(data.stencils[5].own_slot, 2);
  EXPECT_EQ(data.stencils[5].weights.col(2), Eigen::Vector2d::Zero());
  EXPECT_EQ(data.stencils[8].window, std::vector<int>({4, 5, 6, 7, 8}));
  for (size_t f = 0; f < data.times.size(); ++f) {
    if (f == 2) continue;
    SCOPED_TRACE(f);
    const TranslationStencil& stencil = data.stencils[f];
    ASSERT_EQ(stencil.weights.cols(),
              static_cast<int>(stencil.window.size()));
    EXPECT_EQ(stencil.window[stencil.own_slot], static_cast<int>(f));
    if (f != 5) EXPECT_NE(stencil.weights.col(stencil.own_slot).norm(), 0);
    const Rigid3d world_from_rig = data.poses[f]->Inverse();
    TranslationDerivatives from_rigid = TranslationDerivatives::Zero();
    std::vector<const double*> window_poses;
    for (size_t j = 0; j < stencil.window.size(); ++j) {
      const Rigid3d knot = data.poses[stencil.window[j]]->Inverse();
      const Eigen::Vector3d p = world_from_rig.RotationMatrix().transpose() *
                                (knot.translation - world_from_rig.translation);
      from_rigid.head<3>() += stencil.weights(0, j) * p;
      from_rigid.tail<3>() += stencil.weights(1, j) * p;
      window_poses.push_back(data.rig_poses[stencil.window[j]]);
    }
    TranslationDerivatives from_parameters;
    PolynomialTranslation(stencil, window_poses.data(),
                          from_parameters.data());
    for (int k = 0; k < 6; ++k) {
      const double scale = 1 + std::abs(data.Polynomial(f)(k));
      EXPECT_NEAR(from_rigid(k), data.Polynomial(f)(k), 1e-11 * scale) << k;
      EXPECT_NEAR(from_parameters(k), data.Polynomial(f)(k), 1e-11 * scale)
          << k;
    }
  }
}

// term.cost's residuals against rows first_row and first_row + 1 of
// `expected`, and central differences over every value of every block
// against its Jacobians.
void ExpectRowPairAndJacobians(const TranslationPriorTerm& term,
                               const Eigen::Matrix<double, 6, 1>& expected,
                               int first_row, double tolerance) {
  double values[2];
  ASSERT_TRUE(term.cost->Evaluate(term.parameters.data(), values, nullptr));
  EXPECT_NEAR(values[0], expected(first_row), tolerance);
  EXPECT_NEAR(values[1], expected(first_row + 1), tolerance);
  const std::vector<int32_t>& sizes = term.cost->parameter_block_sizes();
  ASSERT_EQ(sizes.size(), term.parameters.size());
  std::vector<std::vector<double>> jacobians;
  std::vector<double*> jacobian_pointers;
  for (const int32_t size : sizes) {
    jacobians.emplace_back(2 * size);
    jacobian_pointers.push_back(jacobians.back().data());
  }
  double residuals[2];
  ASSERT_TRUE(term.cost->Evaluate(term.parameters.data(), residuals,
                                  jacobian_pointers.data()));
  for (size_t block = 0; block < sizes.size(); ++block) {
    for (int k = 0; k < sizes[block]; ++k) {
      double* value = term.parameters[block] + k;
      const double saved = *value, step = 1e-6;
      double plus[2], minus[2];
      *value = saved + step;
      ASSERT_TRUE(term.cost->Evaluate(term.parameters.data(), plus, nullptr));
      *value = saved - step;
      ASSERT_TRUE(
          term.cost->Evaluate(term.parameters.data(), minus, nullptr));
      *value = saved;
      for (int row = 0; row < 2; ++row) {
        const double numeric = (plus[row] - minus[row]) / (2 * step);
        EXPECT_NEAR(jacobians[block][sizes[block] * row + k], numeric,
                    1e-6 * (1 + std::abs(numeric)))
            << "block " << block << " value " << k << " row " << row;
      }
    }
  }
}

// The first frameset of a run: r = W_d (e_f - [p1_f, p2_f]) in three row
// pairs, [p1, p2] the polynomial through its window's poses as parameters
// (e_f, then the five poses); Jacobians against central differences; the
// poses, the weights and the prior read at every evaluation.
TEST(TranslationPriorResidual, ResidualAndJacobiansOverTheWindowsPoses) {
  StencilCase data;
  TranslationPrior prior;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) {
      prior.whitening(i, j) = i == j ? 2 : 0.1 * (i + j);
    }
  }
  prior.innovation_whitening.setConstant(100);  // not read
  std::vector<TranslationDerivatives> estimates(data.times.size());
  for (size_t f = 0; f < estimates.size(); ++f) {
    estimates[f] = data.Polynomial(static_cast<int>(f)) +
                   TranslationDerivatives::LinSpaced(6, 0.1, 0.6);
  }
  std::vector<TranslationPriorTerm> terms = MakeTranslationPriorTerms(
      data.stencils, data.rig_poses, &estimates, 0, false, &prior);
  ASSERT_EQ(terms.size(), 3u);
  const Eigen::Matrix<double, 6, 1> expected =
      prior.whitening * TranslationDerivatives::LinSpaced(6, 0.1, 0.6);
  for (int t = 0; t < 3; ++t) {
    SCOPED_TRACE(t);
    const TranslationPriorTerm& term = terms[t];
    ASSERT_EQ(term.parameters.size(), 6u);
    EXPECT_EQ(term.parameters[0], estimates[0].data());
    for (int j = 0; j < 5; ++j) {
      EXPECT_EQ(term.parameters[1 + j],
                data.rig_poses[data.stencils[0].window[j]]);
    }
    ExpectRowPairAndJacobians(term, expected, 2 * t, 1e-10);
  }
  // A knot moved 1 cm along x: the velocity by its weight times R_f^T x.
  const TranslationPriorTerm& first = terms[0];
  double before[2], after[2];
  ASSERT_TRUE(first.cost->Evaluate(first.parameters.data(), before, nullptr));
  const Rigid3d moved_world_from_rig(
      data.poses[1]->Inverse().rotation,
      data.poses[1]->Inverse().translation + Eigen::Vector3d(0.01, 0, 0));
  data.pose_params[1] = ToPoseParams(moved_world_from_rig.Inverse());
  ASSERT_TRUE(first.cost->Evaluate(first.parameters.data(), after, nullptr));
  const Eigen::Vector3d moved_p =
      data.poses[0]->Inverse().RotationMatrix().transpose() *
      Eigen::Vector3d(0.01, 0, 0);
  TranslationDerivatives change;
  change << data.stencils[0].weights(0, 1) * moved_p,
      data.stencils[0].weights(1, 1) * moved_p;
  const Eigen::Matrix<double, 6, 1> expected_change =
      -prior.whitening * change;
  EXPECT_NEAR(after[0] - before[0], expected_change(0), 1e-9);
  EXPECT_NEAR(after[1] - before[1], expected_change(1), 1e-9);
  // The weights and the prior, read by pointer.
  data.stencils[0].weights.setZero();
  prior.whitening.setIdentity();
  ASSERT_TRUE(first.cost->Evaluate(first.parameters.data(), after, nullptr));
  EXPECT_NEAR(after[0], estimates[0](0), 1e-12);
  EXPECT_NEAR(after[1], estimates[0](1), 1e-12);
}

// After the first of a run: r = W_i (d_f - Phi d_(f-1)), d = e - [p1, p2]
// of each frameset, over e_f, e_(f-1) and the six poses of the two windows
// (frameset 5's {3..7} and 4's {1, 3, 4, 5, 6}), each once; Jacobians
// against central differences; without a gain, d_f alone.
TEST(TranslationInnovationResidual, ResidualAndJacobiansOverBothWindows) {
  const StencilCase data;
  TranslationPrior prior;
  prior.whitening.setConstant(100);  // not read
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) {
      prior.innovation_whitening(i, j) = i == j ? 3 : 0.05 * (i - 2 * j);
      prior.predecessor_gain(i, j) = i == j ? -0.6 : 0.02 * (i + j);
    }
  }
  const TranslationDerivatives deviation =
      TranslationDerivatives::LinSpaced(6, 0.1, 0.6);
  const TranslationDerivatives previous_deviation =
      TranslationDerivatives::LinSpaced(6, 0, -0.25);
  std::vector<TranslationDerivatives> estimates(data.times.size());
  estimates[5] = data.Polynomial(5) + deviation;
  estimates[4] = data.Polynomial(4) + previous_deviation;
  std::vector<TranslationPriorTerm> terms = MakeTranslationPriorTerms(
      data.stencils, data.rig_poses, &estimates, 5, true, &prior);
  ASSERT_EQ(terms.size(), 3u);
  const Eigen::Matrix<double, 6, 1> expected =
      prior.innovation_whitening *
      (deviation - prior.predecessor_gain * previous_deviation);
  const std::vector<int> framesets = {3, 4, 5, 6, 7, 1};
  for (int t = 0; t < 3; ++t) {
    SCOPED_TRACE(t);
    const TranslationPriorTerm& term = terms[t];
    ASSERT_EQ(term.parameters.size(), 8u);
    EXPECT_EQ(term.parameters[0], estimates[5].data());
    EXPECT_EQ(term.parameters[1], estimates[4].data());
    for (int j = 0; j < 6; ++j) {
      EXPECT_EQ(term.parameters[2 + j], data.rig_poses[framesets[j]]);
    }
    ExpectRowPairAndJacobians(term, expected, 2 * t, 1e-9);
  }
  prior.predecessor_gain.setZero();
  double residuals[2];
  ASSERT_TRUE(terms[0].cost->Evaluate(terms[0].parameters.data(), residuals,
                                      nullptr));
  const Eigen::Matrix<double, 6, 1> own =
      prior.innovation_whitening * deviation;
  EXPECT_NEAR(residuals[0], own(0), 1e-9);
  EXPECT_NEAR(residuals[1], own(1), 1e-9);
}

}  // namespace frameset_motion_test
}  // namespace rig_calibrator
