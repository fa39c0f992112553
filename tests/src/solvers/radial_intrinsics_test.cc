#include "src/solvers/radial_intrinsics.h"

#include <colmap/base/camera_models.h>
#include <gtest/gtest.h>

#include <vector>

#include "tests/src/solvers/radial_intrinsics_scene.h"

namespace rig_calibrator {
namespace radial_intrinsics_test {

using testing::MakeRadialIntrinsics;

// The projection agrees with COLMAP's models whose radial part it is.
TEST(RadialIntrinsics, ProjectMatchesColmapModels) {
  struct Case {
    RadialIntrinsics model;
    int colmap_model_id;
    std::vector<double> colmap_params;
  };
  for (const Case& c : {Case{MakeRadialIntrinsics(RadialProfile::kPolynomial, 2,
                                                  0.7, 500, -0.3, 0.08),
                             colmap::RadialCameraModel::kModelId,
                             {500, 0, 0, -0.3, 0.08}},
                        Case{MakeRadialIntrinsics(RadialProfile::kEquidistant,
                                                  2, 0.7, 300, 0.03, -0.005),
                             colmap::RadialFisheyeCameraModel::kModelId,
                             {300, 0, 0, 0.03, -0.005}}}) {
    for (const Eigen::Vector3d& point_cam :
         {Eigen::Vector3d(1, -2, 4), Eigen::Vector3d(-3, 0.5, 1.2),
          Eigen::Vector3d(1e-12, 0, 3)}) {
      const double depth = point_cam.z() + 0.7;
      Eigen::Vector2d x, expected;
      ASSERT_TRUE(c.model.Project(point_cam, &x));
      colmap::CameraModelWorldToImage(
          c.colmap_model_id, c.colmap_params, point_cam.x() / depth,
          point_cam.y() / depth, &expected.x(), &expected.y());
      EXPECT_LT((x - expected).norm(), 1e-9);
    }
    Eigen::Vector2d x;
    EXPECT_FALSE(c.model.Project(Eigen::Vector3d(1, 1, -0.7), &x));
  }
}

TEST(RadialIntrinsics, SignedRadialCoordinateAndProfileAngle) {
  EXPECT_DOUBLE_EQ(SignedRadialCoordinate(Eigen::Vector2d(3, 4),
                                          Eigen::Vector3d(0.6, 0.8, 5)),
                   1);
  EXPECT_DOUBLE_EQ(SignedRadialCoordinate(Eigen::Vector2d(3, 4),
                                          Eigen::Vector3d(-1.2, -1.6, 5)),
                   -2);
  EXPECT_EQ(
      SignedRadialCoordinate(Eigen::Vector2d::Zero(), Eigen::Vector3d(1, 1, 5)),
      0);
  EXPECT_DOUBLE_EQ(ProfileAngle(RadialProfile::kPolynomial, 2, 4), 0.5);
  EXPECT_DOUBLE_EQ(ProfileAngle(RadialProfile::kEquidistant, 2, 2),
                   testing::kPi / 4);
  EXPECT_DOUBLE_EQ(ProfileAngle(RadialProfile::kEquidistant, -2, 2),
                   -testing::kPi / 4);
}

// r_d = f q (1 - 0.3 q^2) grows up to q^2 = 1/0.9: points up to q = 1 pass,
// a point at q = 1.1 fails; k2 > 0 brings the growth back only through the
// vertex of 1 + 3 k1 t + 5 k2 t^2, which is tested too.
TEST(RadialIntrinsics, RadiusGrowsOverPoints) {
  RadialIntrinsics model =
      MakeRadialIntrinsics(RadialProfile::kPolynomial, 1, 0, 500, -0.3, 0);
  const std::vector<Eigen::Vector2d> x = {Eigen::Vector2d(100, 0)};
  EXPECT_TRUE(RadiusGrowsOverPoints(x, {Eigen::Vector3d(1, 0, 1)}, model));
  EXPECT_FALSE(RadiusGrowsOverPoints(x, {Eigen::Vector3d(1.1, 0, 1)}, model));
  // A point on the wrong half-line counts by its angle.
  EXPECT_FALSE(RadiusGrowsOverPoints(x, {Eigen::Vector3d(-1.1, 0, 1)}, model));
  // 1 - 1.2 t + 0.4 t^2: minimum 0.1 at t = 1.5, positive on every range;
  // 1 - 1.2 t + 0.35 t^2: minimum < 0 at t = 1.71, negative between the ends.
  model.num_radial_terms = 2;
  model.k[0] = -0.4;
  model.k[1] = 0.08;
  EXPECT_TRUE(RadiusGrowsOverPoints(x, {Eigen::Vector3d(2, 0, 1)}, model));
  model.k[1] = 0.07;
  EXPECT_FALSE(RadiusGrowsOverPoints(x, {Eigen::Vector3d(2, 0, 1)}, model));
  model.focal = -500;
  EXPECT_FALSE(RadiusGrowsOverPoints(x, {Eigen::Vector3d(0.1, 0, 1)}, model));
}

}  // namespace radial_intrinsics_test
}  // namespace rig_calibrator
