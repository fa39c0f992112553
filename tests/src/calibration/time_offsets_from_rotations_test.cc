#include "src/calibration/time_offsets_from_rotations.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>

#include "src/geometry/pose_interpolation.h"
#include "src/geometry/rigid3d.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace time_offsets_from_rotations_test {

constexpr double kDegToRad = M_PI / 180.0;

// cam_from_rig rotations of four cameras looking forward, left, back and
// right, tilted down a little (the reference camera's is the identity).
std::vector<Eigen::Quaterniond> RingCamFromRig() {
  std::vector<Eigen::Quaterniond> rotations;
  for (int c = 0; c < 4; ++c) {
    rotations.emplace_back(
        Eigen::AngleAxisd(0.1 * c, Eigen::Vector3d::UnitX()) *
        Eigen::AngleAxisd(c * M_PI / 2, Eigen::Vector3d::UnitY()));
  }
  return rotations;
}

struct Scenario {
  std::function<Rigid3d(double)> world_from_rig = testing::SmoothWalkWorldFromBody;
  int num_framesets = 60;
  double frame_interval = 0.2;  // 5 Hz
  std::vector<double> offsets = {0.0, 0.0401, -0.0327, 0.0356};
  double rotation_noise_rad = 0.0;  // per axis
  double wrong_fraction = 0.0;      // 5-40 deg off about a random axis
  double missing_fraction = 0.0;
  unsigned seed = 1;
};

// R_{c,f} = Q_c R_rig(t_f + delta_c), rotated by Exp(noise), some missing,
// some wrong.
RotationTimeOffsetProblem Generate(const Scenario& scenario) {
  std::mt19937 rng(scenario.seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform;
  const std::vector<Eigen::Quaterniond> cam_from_rig = RingCamFromRig();
  RotationTimeOffsetProblem problem;
  for (int f = 0; f < scenario.num_framesets; ++f) {
    problem.frameset_times_s.push_back(3.0 + f * scenario.frame_interval);
  }
  for (size_t c = 0; c < scenario.offsets.size(); ++c) {
    std::vector<std::optional<Eigen::Quaterniond>> rotations;
    for (double t : problem.frameset_times_s) {
      if (uniform(rng) < scenario.missing_fraction) {
        rotations.emplace_back();
        continue;
      }
      Eigen::Matrix3d rotation =
          cam_from_rig[c].toRotationMatrix() *
          scenario.world_from_rig(t + scenario.offsets[c]).RotationMatrix().transpose();
      rotation = ExpSO3(scenario.rotation_noise_rad *
                        Eigen::Vector3d(normal(rng), normal(rng), normal(rng))) *
                 rotation;
      if (uniform(rng) < scenario.wrong_fraction) {
        const Eigen::Vector3d axis =
            Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
        rotation = ExpSO3((5 + 35 * uniform(rng)) * kDegToRad * axis) * rotation;
      }
      rotations.emplace_back(Eigen::Quaterniond(rotation));
    }
    problem.cam_from_world.push_back(rotations);
  }
  return problem;
}

std::vector<RotationTimeOffset> Estimate(const RotationTimeOffsetProblem& problem,
                                         const RotationTimeOffsetOptions& options) {
  std::vector<RotationTimeOffset> offsets;
  std::string error;
  EXPECT_TRUE(EstimateTimeOffsetsFromRotations(problem, options, &offsets, &error))
      << error;
  return offsets;
}

// The rig turning about a fixed axis by a cubic angle: PoseTrajectory
// reproduces the reference's orientation exactly, so the profile is 0 at the
// true offsets, which are found to the golden-section tolerance.
TEST(TimeOffsetsFromRotations, ExactOnTheInterpolantsOwnClass) {
  Scenario scenario;
  const Eigen::Vector3d axis = Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  scenario.world_from_rig = [axis](double t) {
    const double s = t - 3.0;
    return Rigid3d(ExpSO3((0.9 * s - 0.12 * s * s + 0.005 * s * s * s) * axis),
                   Eigen::Vector3d::Zero());
  };
  RotationTimeOffsetOptions options;
  options.tolerance_s = 1e-10;
  const std::vector<RotationTimeOffset> offsets =
      Estimate(Generate(scenario), options);
  ASSERT_EQ(offsets.size(), 4u);
  const std::vector<Eigen::Quaterniond> cam_from_rig = RingCamFromRig();
  for (int c = 0; c < 4; ++c) {
    EXPECT_TRUE(offsets[c].found) << c << ": " << offsets[c].diagnosis;
    EXPECT_NEAR(offsets[c].offset_s, scenario.offsets[c], 1e-8) << c;
    EXPECT_LT(RotationDifferenceRad(offsets[c].cam_from_rig, cam_from_rig[c]), 1e-7)
        << c;
    std::printf("own class: camera %d offset error %.1e s\n", c,
                offsets[c].offset_s - scenario.offsets[c]);
  }
}

// The smooth walk (turning at up to 65 deg/s) at 5 Hz, exact orientations,
// 12 s: the interpolation's own error (0.004 deg, 0.016 deg in the end
// segments) is what is left.
TEST(TimeOffsetsFromRotations, ExactSmoothWalkAtFiveHertz) {
  Scenario scenario;
  const std::vector<RotationTimeOffset> offsets =
      Estimate(Generate(scenario), RotationTimeOffsetOptions());
  for (int c = 1; c < 4; ++c) {
    EXPECT_TRUE(offsets[c].found) << c << ": " << offsets[c].diagnosis;
    EXPECT_NEAR(offsets[c].offset_s, scenario.offsets[c], 0.05e-3) << c;
    std::printf("exact walk: camera %d offset error %.2e s\n", c,
                offsets[c].offset_s - scenario.offsets[c]);
  }
}

// Noisy orientations (0.05 deg per axis), 10 % wrong by 5-40 deg, 10 %
// missing, 60 framesets (12 s): within 1 ms (measured over 30 draws: at most
// 0.86 ms; with 20 % wrong up to 2 ms, with 20 framesets up to 5.7 ms).
TEST(TimeOffsetsFromRotations, NoisyWithWrongAndMissingOrientations) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    Scenario scenario;
    scenario.rotation_noise_rad = 0.05 * kDegToRad;
    scenario.wrong_fraction = 0.1;
    scenario.missing_fraction = 0.1;
    scenario.seed = seed;
    const std::vector<RotationTimeOffset> offsets =
        Estimate(Generate(scenario), RotationTimeOffsetOptions());
    for (int c = 1; c < 4; ++c) {
      EXPECT_TRUE(offsets[c].found) << seed << " " << c << ": "
                                    << offsets[c].diagnosis;
      EXPECT_NEAR(offsets[c].offset_s, scenario.offsets[c], 1e-3)
          << seed << " " << c;
      std::printf("noisy, seed %u: camera %d offset error %+.3f ms\n", seed, c,
                  (offsets[c].offset_s - scenario.offsets[c]) * 1e3);
    }
  }
}

// A rig that does not turn, or turns at a constant rate about a fixed axis:
// every offset fits, none is reported.
TEST(TimeOffsetsFromRotations, NoOffsetWithoutChangingRotation) {
  for (const double rate : {0.0, 0.8}) {
    Scenario scenario;
    scenario.world_from_rig = [rate](double t) {
      return Rigid3d(ExpSO3(rate * t * Eigen::Vector3d::UnitZ()),
                     Eigen::Vector3d(1.5 * t, 0, 0));
    };
    scenario.rotation_noise_rad = 0.05 * kDegToRad;
    const std::vector<RotationTimeOffset> offsets =
        Estimate(Generate(scenario), RotationTimeOffsetOptions());
    for (int c = 1; c < 4; ++c) {
      EXPECT_FALSE(offsets[c].found) << rate << " " << c;
      EXPECT_FALSE(offsets[c].diagnosis.empty()) << rate << " " << c;
      EXPECT_TRUE(std::isfinite(offsets[c].offset_s));
    }
  }
}

TEST(TimeOffsetsFromRotations, TooFewFramesetsAndBadInput) {
  Scenario scenario;
  scenario.num_framesets = 6;
  RotationTimeOffsetProblem problem = Generate(scenario);
  std::vector<RotationTimeOffset> offsets = Estimate(problem, RotationTimeOffsetOptions());
  EXPECT_FALSE(offsets[1].found);
  EXPECT_NE(offsets[1].diagnosis.find("8 needed"), std::string::npos)
      << offsets[1].diagnosis;

  std::string error;
  problem.reference_camera = 4;
  EXPECT_FALSE(EstimateTimeOffsetsFromRotations(problem, RotationTimeOffsetOptions(),
                                                &offsets, &error));
  EXPECT_NE(error.find("reference camera"), std::string::npos) << error;
  problem.reference_camera = 0;
  problem.frameset_times_s[3] = problem.frameset_times_s[2];
  EXPECT_FALSE(EstimateTimeOffsetsFromRotations(problem, RotationTimeOffsetOptions(),
                                                &offsets, &error));
  EXPECT_NE(error.find("strictly increasing"), std::string::npos) << error;
}

}  // namespace time_offsets_from_rotations_test
}  // namespace rig_calibrator
