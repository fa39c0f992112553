// The final bundle adjustment with the map images' observations
// (use_map_observations) and with the map adjusted too (refine_map), on the
// synthetic generator's rigs with map images (src/synthetic/synthetic_map.h):
// exact data give the truth, noisy data a bound, bad map observations are
// rejected.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <unordered_map>
#include <unordered_set>

#include "src/calibration/final_bundle_adjuster.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {
namespace final_bundle_adjuster_map_images_test {

// A ring5 dataset with map images whose map points are `map_point_noise`
// off; with `only_map_observed`, the rig keeps only correspondences of points
// that some map image observes (then every refined point is determined by
// exact observations from fixed map poses).
SyntheticRig MakeRig(double noise_px, double map_point_noise,
                     bool only_map_observed, unsigned seed = 3) {
  SyntheticRigOptions options;
  options.num_framesets = 10;
  options.points_per_image = 120;
  options.noise_px = noise_px;
  options.map_noise_px = noise_px;
  options.outlier_ratio = 0;
  options.missing_image_ratio = 0;
  options.num_map_images = 25;
  options.map_point_noise = map_point_noise;
  options.seed = seed;
  SyntheticRig rig = GenerateSyntheticRig(options);
  if (only_map_observed) {
    std::unordered_set<int64_t> observed;
    for (const MapImage& image : rig.dataset.map_images) {
      for (const MapObservation& observation : image.observations) {
        observed.insert(observation.point3D_id);
      }
    }
    for (RigImage& image : rig.dataset.images) {
      image.correspondences.erase(
          std::remove_if(
              image.correspondences.begin(), image.correspondences.end(),
              [&](const Correspondence& correspondence) {
                return observed.count(correspondence.point3D_id) == 0;
              }),
          image.correspondences.end());
    }
  }
  return rig;
}

// The truth, perturbed: intrinsics (focal 1 %, principal point 3 px),
// cam_from_rig and rig_from_world (0.3 deg, 1 cm); every correspondence an
// inlier.
RigCalibration PerturbedStart(const SyntheticRig& rig) {
  std::mt19937 rng(11);
  std::normal_distribution<double> gaussian(0, 1);
  const auto perturb = [&](const Rigid3d& pose) {
    const Eigen::Vector3d axis =
        Eigen::Vector3d(gaussian(rng), gaussian(rng), gaussian(rng))
            .normalized();
    return Rigid3d(
        Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * M_PI / 180, axis)) *
            pose.rotation,
        pose.translation + 0.01 * axis);
  };
  RigCalibration start;
  start.cameras = rig.truth.cameras;
  start.cam_from_rig = rig.truth.cam_from_rig;
  start.camera_calibrated.assign(start.cameras.size(), true);
  for (size_t c = 0; c < start.cameras.size(); ++c) {
    std::vector<double>& params = start.cameras[c].Params();
    params[0] *= 1.01;
    params[1] *= 0.99;
    params[2] += 3;
    params[3] -= 3;
    if (static_cast<int>(c) != rig.dataset.reference_camera) {
      start.cam_from_rig[c] = perturb(start.cam_from_rig[c]);
    }
  }
  for (const Rigid3d& pose : rig.truth.rig_from_world) {
    start.rig_from_world.push_back(perturb(pose));
  }
  for (const RigImage& image : rig.dataset.images) {
    ImageResult result;
    result.localized = true;
    result.inlier_mask.assign(image.correspondences.size(), 1);
    start.images.push_back(result);
  }
  return start;
}

// Largest errors, except `point`: the median over the refined points (a
// point seen by two nearly parallel rays is poorly determined by any method).
struct Errors {
  double rotation_deg = 0, center = 0, focal_relative = 0, point = 0,
         map_center = 0;
};

double AngleDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return a.angularDistance(b) * 180 / M_PI;
}

// Errors against the truth: cam_from_rig and rig_from_world
// rotations and centers, focal lengths, refined points, map image centers.
Errors Compare(const SyntheticRig& rig, const RigCalibration& estimate) {
  Errors errors;
  for (size_t c = 0; c < rig.truth.cameras.size(); ++c) {
    errors.rotation_deg = std::max(
        errors.rotation_deg, AngleDeg(estimate.cam_from_rig[c].rotation,
                                      rig.truth.cam_from_rig[c].rotation));
    errors.center = std::max(errors.center, (estimate.cam_from_rig[c].Center() -
                                             rig.truth.cam_from_rig[c].Center())
                                                .norm());
    for (int k : {0, 1}) {
      errors.focal_relative = std::max(
          errors.focal_relative, std::abs(estimate.cameras[c].Params()[k] /
                                              rig.truth.cameras[c].Params()[k] -
                                          1));
    }
  }
  for (size_t j = 0; j < rig.truth.rig_from_world.size(); ++j) {
    errors.rotation_deg = std::max(
        errors.rotation_deg, AngleDeg(estimate.rig_from_world[j]->rotation,
                                      rig.truth.rig_from_world[j].rotation));
    errors.center =
        std::max(errors.center, (estimate.rig_from_world[j]->Center() -
                                 rig.truth.rig_from_world[j].Center())
                                    .norm());
  }
  std::vector<double> point_errors;
  for (const auto& [point3D_id, point] : estimate.refined_points3D) {
    point_errors.push_back((point - rig.true_points3D[point3D_id]).norm());
  }
  if (!point_errors.empty()) {
    std::nth_element(point_errors.begin(),
                     point_errors.begin() + point_errors.size() / 2,
                     point_errors.end());
    errors.point = point_errors[point_errors.size() / 2];
  }
  for (size_t i = 0; i < estimate.map_cam_from_world.size(); ++i) {
    errors.map_center =
        std::max(errors.map_center, (estimate.map_cam_from_world[i].Center() -
                                     rig.true_map_cam_from_world[i].Center())
                                        .norm());
  }
  return errors;
}

void Print(const char* label, const Errors& e,
           const FinalBundleAdjustmentSummary& summary) {
  std::printf(
      "%s: rotation %.3g deg, center %.3g, focal %.3g, point %.3g, map "
      "center %.3g; rig rms %.3g -> %.3g px (%d), map rms %.3g -> %.3g px "
      "(%d, %d rejected), %.2f s\n",
      label, e.rotation_deg, e.center, e.focal_relative, e.point, e.map_center,
      summary.initial_rms_px, summary.final_rms_px, summary.num_residuals,
      summary.map_initial_rms_px, summary.map_final_rms_px,
      summary.num_map_residuals, summary.num_map_outliers, summary.seconds);
}

FinalBundleAdjustmentOptions MapOptions() {
  FinalBundleAdjustmentOptions options;
  options.refine_points = true;
  options.use_map_observations = true;
  options.num_threads = 2;
  return options;
}

TEST(FinalBundleAdjusterMapImagesTest,
     ExactMapObservationsCorrectTheMapPoints) {
  // The map points are 3 cm off, every observation is exact: the map
  // images' observations (from their fixed true poses) put every refined
  // point back at the truth, and the rig with it.
  const SyntheticRig rig = MakeRig(0, 0.03, /*only_map_observed=*/true);
  RigCalibration calibration = PerturbedStart(rig);
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(MapOptions(), rig.dataset, &calibration, &summary));
  const Errors errors = Compare(rig, calibration);
  Print("exact, map observations", errors, summary);
  EXPECT_GT(summary.num_map_residuals, 1000);
  EXPECT_LT(errors.rotation_deg, 1e-8);
  EXPECT_LT(errors.center, 1e-8);
  EXPECT_LT(errors.focal_relative, 1e-9);
  EXPECT_LT(errors.point, 1e-8);
  EXPECT_LT(summary.map_final_rms_px, 1e-7);
  EXPECT_EQ(summary.num_map_outliers, 0);
  ASSERT_EQ(calibration.map_cam_from_world.size(),
            rig.dataset.map_images.size());
  EXPECT_LT(errors.map_center, 1e-12);  // held fixed
}

TEST(FinalBundleAdjusterMapImagesTest, ExactRefineMapReturnsToTheTruth) {
  // The map adjusted with the rig (free gauge, then aligned to the input
  // map's camera centres, here the true ones): the truth again.
  const SyntheticRig rig = MakeRig(0, 0.03, /*only_map_observed=*/true);
  RigCalibration calibration = PerturbedStart(rig);
  FinalBundleAdjustmentOptions options = MapOptions();
  options.refine_map = true;
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(options, rig.dataset, &calibration, &summary));
  const Errors errors = Compare(rig, calibration);
  Print("exact, refine_map", errors, summary);
  EXPECT_LT(errors.rotation_deg, 1e-7);
  EXPECT_LT(errors.center, 1e-7);
  EXPECT_LT(errors.focal_relative, 1e-8);
  EXPECT_LT(errors.point, 1e-7);
  EXPECT_LT(errors.map_center, 1e-7);
}

TEST(FinalBundleAdjusterMapImagesTest, NoisyMapObservationsBeatRigOnlyPoints) {
  // 0.5 px noise everywhere, map points 2 cm off: with the map images'
  // observations the points and the rig are more accurate than from the
  // rig images alone.
  const SyntheticRig rig = MakeRig(0.5, 0.02, /*only_map_observed=*/false);
  FinalBundleAdjustmentOptions rig_only = MapOptions();
  rig_only.use_map_observations = false;
  RigCalibration without = PerturbedStart(rig);
  FinalBundleAdjustmentSummary summary_without;
  ASSERT_TRUE(AdjustRig(rig_only, rig.dataset, &without, &summary_without));
  const Errors errors_without = Compare(rig, without);
  Print("noisy, rig images only", errors_without, summary_without);

  RigCalibration with = PerturbedStart(rig);
  FinalBundleAdjustmentSummary summary_with;
  ASSERT_TRUE(AdjustRig(MapOptions(), rig.dataset, &with, &summary_with));
  const Errors errors_with = Compare(rig, with);
  Print("noisy, map observations", errors_with, summary_with);

  EXPECT_LT(errors_with.rotation_deg, 0.1);
  EXPECT_LT(errors_with.center, 0.004);
  EXPECT_LT(errors_with.focal_relative, 1e-3);
  EXPECT_LT(errors_with.rotation_deg, errors_without.rotation_deg);
  EXPECT_LT(errors_with.center, errors_without.center);
  EXPECT_LT(errors_with.point, errors_without.point);
  EXPECT_LT(summary_with.map_final_rms_px, 0.8);
}

TEST(FinalBundleAdjusterMapImagesTest, BadMapObservationsAreRejected) {
  // Every 33rd map observation of a point with 5 map observations or more
  // moved by 25 px: rejected (reported per observation for the output
  // model), the rest unaffected.
  SyntheticRig rig = MakeRig(0, 0.03, /*only_map_observed=*/true);
  std::unordered_map<int64_t, int> num_map_observations;
  for (const MapImage& image : rig.dataset.map_images) {
    for (const MapObservation& observation : image.observations) {
      ++num_map_observations[observation.point3D_id];
    }
  }
  std::vector<std::vector<char>> corrupted;
  for (MapImage& image : rig.dataset.map_images) {
    corrupted.emplace_back(image.observations.size(), 0);
    for (size_t k = 0; k < image.observations.size(); k += 33) {
      if (num_map_observations[image.observations[k].point3D_id] >= 5) {
        image.observations[k].point2D += Eigen::Vector2d(25, 0);
        corrupted.back()[k] = 1;
      }
    }
  }
  RigCalibration calibration = PerturbedStart(rig);
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(MapOptions(), rig.dataset, &calibration, &summary));
  const Errors errors = Compare(rig, calibration);
  Print("exact with bad map observations", errors, summary);
  EXPECT_LT(errors.center, 1e-6);
  EXPECT_LT(errors.point, 1e-6);
  int num_missed = 0, num_wrongly_rejected = 0, num_in_problem = 0;
  std::unordered_set<int64_t> refined;
  for (const auto& [point3D_id, point] : calibration.refined_points3D) {
    refined.insert(point3D_id);
  }
  for (size_t i = 0; i < rig.dataset.map_images.size(); ++i) {
    const MapImage& image = rig.dataset.map_images[i];
    for (size_t k = 0; k < image.observations.size(); ++k) {
      if (refined.count(image.observations[k].point3D_id) == 0) continue;
      ++num_in_problem;
      const bool rejected = calibration.map_observation_rejected[i][k];
      num_missed += corrupted[i][k] && !rejected ? 1 : 0;
      num_wrongly_rejected += !corrupted[i][k] && rejected ? 1 : 0;
    }
  }
  std::printf(
      "%d map observations of refined points, %d bad ones kept, %d "
      "good ones rejected\n",
      num_in_problem, num_missed, num_wrongly_rejected);
  EXPECT_EQ(num_missed, 0);
  EXPECT_LE(num_wrongly_rejected, num_in_problem / 1000);
}

TEST(FinalBundleAdjusterMapImagesTest, RefineMapNeedsMapImages) {
  SyntheticRigOptions options;
  options.num_framesets = 4;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  RigCalibration calibration = PerturbedStart(rig);
  FinalBundleAdjustmentOptions ba_options = MapOptions();
  ba_options.refine_map = true;
  EXPECT_FALSE(AdjustRig(ba_options, rig.dataset, &calibration, nullptr));
}

}  // namespace final_bundle_adjuster_map_images_test
}  // namespace rig_calibrator
