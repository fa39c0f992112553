// The final bundle adjustment with refined map points: the refinement, and
// the gauge (map_anchoring.h): fixed points hold the world frame; with none,
// the solution is moved onto the map.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <unordered_map>
#include <unordered_set>

#include "src/calibration/final_bundle_adjuster.h"
#include "src/geometry/rigid3d.h"
#include "tests/src/calibration/final_ba_scene.h"

namespace rig_calibrator {
namespace final_bundle_adjuster_map_points_test {

using namespace final_ba_testing;  // NOLINT: the shared test fixture

// The shared-point scene for map-point refinement, started at the truth with
// every correspondence an inlier. Every `fixed_every`-th correspondence of
// each image (0: none) becomes a point of its own (id -1, held fixed at its
// true position); points with an id that are seen once are dropped, so that
// every point with an id is refined.
struct MapPointScene {
  SyntheticBaScene rig;
  RigDataset dataset;
  RigCalibration start;
  std::unordered_map<int64_t, Eigen::Vector3d> truth_points;
};

MapPointScene MakeMapPointScene(int fixed_every) {
  SceneOptions options;
  options.shared_points = true;
  MapPointScene scene;
  scene.rig = MakeSyntheticRig(options);
  scene.dataset = scene.rig.dataset;
  std::unordered_map<int64_t, int> num_observations;
  for (RigImage& image : scene.dataset.images) {
    for (size_t k = 0; k < image.correspondences.size(); ++k) {
      Correspondence& correspondence = image.correspondences[k];
      if (fixed_every > 0 && k % fixed_every == 0) {
        correspondence.point3D_id = -1;
      } else {
        ++num_observations[correspondence.point3D_id];
      }
    }
  }
  for (RigImage& image : scene.dataset.images) {
    image.correspondences.erase(
        std::remove_if(image.correspondences.begin(),
                       image.correspondences.end(),
                       [&](const Correspondence& correspondence) {
                         return correspondence.point3D_id >= 0 &&
                                num_observations[correspondence.point3D_id] < 2;
                       }),
        image.correspondences.end());
    for (const Correspondence& correspondence : image.correspondences) {
      if (correspondence.point3D_id >= 0) {
        scene.truth_points[correspondence.point3D_id] = correspondence.point3D;
      }
    }
  }
  scene.start = scene.rig.truth;
  for (size_t i = 0; i < scene.dataset.images.size(); ++i) {
    scene.start.images[i].inlier_mask.assign(
        scene.dataset.images[i].correspondences.size(), 1);
  }
  return scene;
}

// Replaces the map position of every point with an id by `map_from_truth`
// (X -> s R X + t, as a 4x4 matrix) applied to it, plus `noise` (standard
// deviation per coordinate) drawn once per point. Returns the map positions.
std::unordered_map<int64_t, Eigen::Vector3d> MoveMapPoints(
    const Eigen::Matrix4d& map_from_truth, double noise, MapPointScene* scene) {
  std::mt19937 rng(6);
  std::normal_distribution<double> gaussian(0, noise);
  std::unordered_map<int64_t, Eigen::Vector3d> map_points;
  for (const auto& [point3D_id, point] : scene->truth_points) {
    map_points[point3D_id] =
        (map_from_truth * point.homogeneous()).head<3>() +
        Eigen::Vector3d(gaussian(rng), gaussian(rng), gaussian(rng));
  }
  for (RigImage& image : scene->dataset.images) {
    for (Correspondence& correspondence : image.correspondences) {
      if (correspondence.point3D_id >= 0) {
        correspondence.point3D = map_points.at(correspondence.point3D_id);
      }
    }
  }
  return map_points;
}

// A similarity the map is off by: 1 % scale, 2 deg, 10 cm.
Eigen::Matrix4d MapFromTruth() {
  Eigen::Matrix4d similarity = Eigen::Matrix4d::Identity();
  similarity.topLeftCorner<3, 3>() =
      1.01 * RotationAboutAxis(colmap::DegToRad(2.0), Eigen::Vector3d(1, 2, 3))
                 .toRotationMatrix();
  similarity.topRightCorner<3, 1>() = Eigen::Vector3d(0.1, -0.05, 0.08);
  return similarity;
}

FinalBundleAdjustmentOptions RefinePoints() {
  FinalBundleAdjustmentOptions options;
  options.refine_points = true;
  return options;
}

// The map moved by MapFromTruth(), then the adjustment with refined points
// from the truth: exact, and every point with an id refined.
RigCalibration AdjustOnMovedMap(MapPointScene* scene) {
  MoveMapPoints(MapFromTruth(), 0, scene);
  RigCalibration calibration = scene->start;
  FinalBundleAdjustmentSummary summary;
  EXPECT_TRUE(
      AdjustRig(RefinePoints(), scene->dataset, &calibration, &summary));
  EXPECT_LT(summary.final_rms_px, 1e-6);
  EXPECT_EQ(calibration.refined_points3D.size(), scene->truth_points.size());
  return calibration;
}

TEST(FinalBundleAdjusterTest, RefinedMapPointsAverageTheMapNoiseOut) {
  // The map is off by 1 cm per point; the observations are exact.
  MapPointScene scene = MakeMapPointScene(/*fixed_every=*/0);
  const std::unordered_map<int64_t, Eigen::Vector3d> map_points =
      MoveMapPoints(Eigen::Matrix4d::Identity(), 0.01, &scene);
  RigCalibration fixed_map = scene.start;
  FinalBundleAdjustmentSummary fixed_summary;
  ASSERT_TRUE(AdjustRig(FinalBundleAdjustmentOptions(), scene.dataset,
                        &fixed_map, &fixed_summary));
  EXPECT_TRUE(fixed_map.refined_points3D.empty());

  RigCalibration calibration = scene.start;
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(RefinePoints(), scene.dataset, &calibration, &summary));
  std::printf("map fixed: rms %.3g px; map refined: rms %.3g px, %zu points\n",
              fixed_summary.final_rms_px, summary.final_rms_px,
              calibration.refined_points3D.size());
  EXPECT_GT(fixed_summary.final_rms_px, 0.5);
  EXPECT_LT(summary.final_rms_px, 1e-6);
  ASSERT_EQ(calibration.refined_points3D.size(), scene.truth_points.size());
  ASSERT_GT(calibration.refined_points3D.size(), 500);
  double map_error = 0, refined_error = 0;
  for (const auto& [point3D_id, point] : calibration.refined_points3D) {
    const Eigen::Vector3d& truth = scene.truth_points.at(point3D_id);
    map_error += (map_points.at(point3D_id) - truth).norm();
    refined_error += (point - truth).norm();
  }
  // Exact observations pin the points down up to the similarity that
  // re-anchors them to the noisy map, which averages the map's noise out.
  EXPECT_LT(refined_error, 0.2 * map_error);
  const CalibrationErrors errors = Compare(calibration, scene.rig.truth);
  EXPECT_LT(errors.focal_relative, 1e-6);
  EXPECT_LT(errors.rotation_deg, 0.01);
}

// Every observed point refined: nothing fixes the world frame, and the
// solution is moved onto the map. The map is the truth moved by a
// similarity and the start is the truth, so the solver alone would stop
// somewhere between the two.
TEST(FinalBundleAdjusterTest, FreeGaugeIsMovedOntoTheMap) {
  MapPointScene scene = MakeMapPointScene(/*fixed_every=*/0);
  const RigCalibration calibration = AdjustOnMovedMap(&scene);
  const Eigen::Matrix4d map_from_truth = MapFromTruth();
  for (const auto& [point3D_id, point] : calibration.refined_points3D) {
    const Eigen::Vector3d map_point =
        (map_from_truth * scene.truth_points.at(point3D_id).homogeneous())
            .head<3>();
    ASSERT_LT((point - map_point).norm(), 1e-6) << point3D_id;
  }
  // The rig keeps its shape and takes the map's scale.
  for (size_t c = 0; c < scene.rig.truth.cam_from_rig.size(); ++c) {
    const Rigid3d& truth = scene.rig.truth.cam_from_rig[c];
    EXPECT_LT(RotationDifferenceDeg(calibration.cam_from_rig[c].rotation,
                                    truth.rotation),
              1e-6);
    EXPECT_LT(
        (calibration.cam_from_rig[c].translation - 1.01 * truth.translation)
            .norm(),
        1e-7);
  }
}

// Some observed points fixed (id -1) at their true positions, the refined
// ones starting on a map moved by a similarity: the fixed points hold the
// world frame, the solution is the truth, and it is not moved onto the map.
TEST(FinalBundleAdjusterTest, FixedPointsHoldTheGauge) {
  MapPointScene scene = MakeMapPointScene(/*fixed_every=*/4);
  const RigCalibration calibration = AdjustOnMovedMap(&scene);
  for (const auto& [point3D_id, point] : calibration.refined_points3D) {
    ASSERT_LT((point - scene.truth_points.at(point3D_id)).norm(), 1e-6)
        << point3D_id;
  }
  const CalibrationErrors errors = Compare(calibration, scene.rig.truth);
  EXPECT_LT(errors.rotation_deg, 1e-6);
  EXPECT_LT(errors.center, 1e-7);
}

// Points seen twice, one of the two observations moved 80 px off: the first
// solve refines them, its pruning leaves them one observation, and the next
// solves hold them at their map position (a point seen once has 3 unknowns
// for 2 residuals), so their observations' costs change from a refined to a
// fixed point between the solves. The result is the truth.
TEST(FinalBundleAdjusterTest, PointsLeftWithOneObservationAreHeldFixed) {
  MapPointScene scene = MakeMapPointScene(/*fixed_every=*/0);
  std::unordered_map<int64_t, int> num_observations;
  for (const RigImage& image : scene.dataset.images) {
    for (const Correspondence& correspondence : image.correspondences) {
      ++num_observations[correspondence.point3D_id];
    }
  }
  std::unordered_set<int64_t> tampered;
  for (RigImage& image : scene.dataset.images) {
    for (Correspondence& correspondence : image.correspondences) {
      const int64_t id = correspondence.point3D_id;
      if (num_observations[id] == 2 && tampered.size() < 40 &&
          tampered.count(id) == 0) {
        correspondence.point2D += Eigen::Vector2d(80, -60);
        tampered.insert(id);
      }
    }
  }
  ASSERT_EQ(tampered.size(), 40);
  RigCalibration calibration = scene.start;
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(RefinePoints(), scene.dataset, &calibration, &summary));
  // Each tampered point loses one observation or, when the split of the
  // first solve put both over the threshold, both.
  EXPECT_GE(summary.num_outliers, 40);
  EXPECT_LE(summary.num_outliers, 80);
  EXPECT_LT(summary.final_rms_px, 1e-6);
  for (const int64_t point3D_id : tampered) {
    EXPECT_EQ(calibration.refined_points3D.count(point3D_id), 0) << point3D_id;
  }
  EXPECT_EQ(calibration.refined_points3D.size() + tampered.size(),
            scene.truth_points.size());
  const CalibrationErrors errors = Compare(calibration, scene.rig.truth);
  EXPECT_LT(errors.rotation_deg, 1e-6);
  EXPECT_LT(errors.center, 1e-7);
}

}  // namespace final_bundle_adjuster_map_points_test
}  // namespace rig_calibrator
