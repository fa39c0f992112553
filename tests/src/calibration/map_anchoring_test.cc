#include "src/calibration/map_anchoring.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

namespace rig_calibrator {
namespace map_anchoring_test {

// A free-gauge solution: the map's points, two rig poses and a cam_from_rig,
// all moved by the similarity X_solution = s R X_map + t, so that every
// projection is the map's. Points 0-2 have map_points3D entries, points 3-5
// only correspondences (both ways AnchorRefinedPointsToMap finds a map
// position).
struct Scene {
  RigDataset dataset;
  RigCalibration map_frame;  // the truth, in map coordinates
  RigCalibration solution;   // the same, in the similarity's frame
};

Scene MakeScene() {
  Scene scene;
  const Eigen::Vector3d points[6] = {{0.3, -0.2, 4.0}, {-1.1, 0.4, 5.5},
                                     {0.9, 0.8, 3.2},  {-0.4, -0.9, 6.1},
                                     {1.5, -0.3, 4.7}, {0.1, 1.2, 5.0}};
  RigImage image;
  for (int64_t id = 0; id < 6; ++id) {
    if (id < 3) {
      scene.dataset.map_points3D[id] = points[id];
    } else {
      Correspondence correspondence;
      correspondence.point3D = points[id];
      correspondence.point3D_id = id;
      image.correspondences.push_back(correspondence);
    }
    scene.map_frame.refined_points3D[id] = points[id];
  }
  scene.dataset.images.push_back(image);
  scene.map_frame.cam_from_rig = {
      Rigid3d(),
      Rigid3d(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()).matrix(),
              Eigen::Vector3d(0.12, 0.01, -0.03))};
  scene.map_frame.rig_from_world = {
      Rigid3d(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()).matrix(),
              Eigen::Vector3d(0.2, -0.1, 0.5)),
      std::nullopt,
      Rigid3d(Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitZ()).matrix(),
              Eigen::Vector3d(-0.4, 0.3, 0.2))};

  // X' = s R X + t, Q' = (R_Q R^T, s t_Q - R_Q R^T t), P' = (R_P, s t_P).
  const double s = 1.7;
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.6, Eigen::Vector3d(1, 2, -1).normalized()).matrix();
  const Eigen::Vector3d t(2.0, -3.0, 0.5);
  scene.solution = scene.map_frame;
  for (auto& [id, point] : scene.solution.refined_points3D) {
    point = s * r * point + t;
  }
  for (std::optional<Rigid3d>& pose : scene.solution.rig_from_world) {
    if (!pose) continue;
    const Eigen::Matrix3d rotation = pose->RotationMatrix() * r.transpose();
    *pose = Rigid3d(rotation, s * pose->translation - rotation * t);
  }
  for (Rigid3d& cam_from_rig : scene.solution.cam_from_rig) {
    cam_from_rig.translation *= s;
  }
  return scene;
}

TEST(AnchorRefinedPointsToMap, MovesAFreeGaugeSolutionOntoTheMap) {
  Scene scene = MakeScene();
  ASSERT_TRUE(AnchorRefinedPointsToMap(scene.dataset, &scene.solution));
  for (const auto& [id, point] : scene.map_frame.refined_points3D) {
    EXPECT_LT((scene.solution.refined_points3D.at(id) - point).norm(), 1e-9)
        << "point " << id;
  }
  for (size_t f : {0, 2}) {
    for (int camera = 0; camera < 2; ++camera) {
      const Rigid3d truth = scene.map_frame.CamFromWorld(camera, f);
      const Rigid3d anchored = scene.solution.CamFromWorld(camera, f);
      EXPECT_LT(RotationDifferenceDeg(truth.rotation, anchored.rotation), 1e-8);
      EXPECT_LT((truth.translation - anchored.translation).norm(), 1e-9);
    }
  }
  EXPECT_FALSE(scene.solution.rig_from_world[1].has_value());
}

TEST(AnchorRefinedPointsToMap, RefusesPointsItCannotPlace) {
  // A refined point with neither a map_points3D entry nor a correspondence.
  Scene scene = MakeScene();
  scene.solution.refined_points3D[7] = Eigen::Vector3d(1, 1, 1);
  const RigCalibration before = scene.solution;
  EXPECT_FALSE(AnchorRefinedPointsToMap(scene.dataset, &scene.solution));
  EXPECT_EQ(scene.solution.refined_points3D, before.refined_points3D);
  EXPECT_EQ(scene.solution.cam_from_rig[1].translation,
            before.cam_from_rig[1].translation);

  // Fewer than 3 points do not determine a similarity.
  Scene few = MakeScene();
  for (int64_t id = 2; id < 6; ++id) few.solution.refined_points3D.erase(id);
  const RigCalibration few_before = few.solution;
  EXPECT_FALSE(AnchorRefinedPointsToMap(few.dataset, &few.solution));
  EXPECT_EQ(few.solution.refined_points3D, few_before.refined_points3D);
}

}  // namespace map_anchoring_test
}  // namespace rig_calibrator
