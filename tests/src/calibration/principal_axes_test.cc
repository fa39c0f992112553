#include "src/calibration/principal_axes.h"

#include <colmap/util/math.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "tests/src/calibration/radial_rig_scene.h"

namespace rig_calibrator {
namespace testing {
namespace principal_axes_test {

// The principal axis of a camera turned by yaw_deg about y from looking
// along +z.
Eigen::Vector3d TurnedAxis(double yaw_deg) {
  return PrincipalAxis(
      Rigid3d(RotationAbout(Eigen::Vector3d::UnitY(), yaw_deg).conjugate(),
              Eigen::Vector3d::Zero()));
}

TEST(AxisAngleFromParallelDeg, FoldsAntiParallelOntoParallel) {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(TurnedAxis(90).dot(Eigen::Vector3d::UnitX()), 1, 1e-15);
  EXPECT_EQ(AxisAngleFromParallelDeg(z, z), 0);
  EXPECT_EQ(AxisAngleFromParallelDeg(z, -z), 0);
  for (const double angle : {2.0, 30.0, 60.0, 89.0}) {
    EXPECT_NEAR(AxisAngleFromParallelDeg(z, TurnedAxis(angle)), angle, 1e-9);
    EXPECT_NEAR(AxisAngleFromParallelDeg(z, TurnedAxis(180 - angle)), angle,
                1e-9);
  }
  EXPECT_NEAR(AxisAngleFromParallelDeg(z, TurnedAxis(90)), 90, 1e-9);
}

// Two axes theta apart: N = 2I - z_a z_a^T - z_b z_b^T has the eigenvalues
// 1 - |cos theta|, 1 + |cos theta|, 2.
TEST(SmallestAxisEigenvalue, TwoAxesGiveOneMinusAbsCosine) {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  for (const double angle : {0.0, 3.0, 45.0, 90.0, 135.0, 177.0, 180.0}) {
    SCOPED_TRACE(angle);
    EXPECT_NEAR(SmallestAxisEigenvalue({z, TurnedAxis(angle)}),
                1 - std::abs(std::cos(colmap::DegToRad(angle))), 1e-12);
  }
  // Three axes spanning space: N = 2I.
  EXPECT_NEAR(SmallestAxisEigenvalue(
                  {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), z}),
              2, 1e-12);
}

TEST(AxesDetermineTranslation, ThresholdAppliesToParallelAndAntiParallel) {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const double limit = kMinDeterminingAxisAngleDeg;
  EXPECT_FALSE(AxesDetermineTranslation({z}));
  EXPECT_FALSE(AxesDetermineTranslation({z, z}));
  EXPECT_FALSE(AxesDetermineTranslation({z, -z}));
  EXPECT_FALSE(AxesDetermineTranslation({z, TurnedAxis(limit - 0.1)}));
  EXPECT_FALSE(AxesDetermineTranslation({z, TurnedAxis(180 - limit + 0.1)}));
  EXPECT_TRUE(AxesDetermineTranslation({z, TurnedAxis(limit + 0.1)}));
  EXPECT_TRUE(AxesDetermineTranslation({z, TurnedAxis(180 - limit - 0.1)}));
  // The cameras' contributions add up: many nearly parallel axes do
  // determine it, N's smallest eigenvalue being their sum.
  EXPECT_FALSE(AxesDetermineTranslation({z, TurnedAxis(178)}));
  EXPECT_TRUE(AxesDetermineTranslation({z, -z, TurnedAxis(4), TurnedAxis(176),
                                        TurnedAxis(-4), TurnedAxis(184)}));
  // An explicit angle.
  EXPECT_FALSE(AxesDetermineTranslation({z, TurnedAxis(20)}, 25));
  EXPECT_TRUE(AxesDetermineTranslation({z, TurnedAxis(20)}, 15));
}

bool PairIsParallel(double yaw_deg, double max_angle_deg,
                    std::string* explanation) {
  const RadialRigScene scene = MakePairScene(yaw_deg);
  return PrincipalAxesAreParallel(scene.dataset, scene.input, max_angle_deg,
                                  explanation);
}

TEST(PrincipalAxesAreParallel, AntiParallelCountsAsParallel) {
  std::string explanation;
  for (const double yaw_deg : {0.0, 2.0, 178.0, 180.0}) {
    SCOPED_TRACE(yaw_deg);
    EXPECT_TRUE(
        PairIsParallel(yaw_deg, kMinDeterminingAxisAngleDeg, &explanation));
    EXPECT_NE(explanation.find("parallel or anti-parallel"), std::string::npos)
        << explanation;
  }
  // The front/back pair's axes are exactly anti-parallel: 0 from parallel.
  PairIsParallel(180, kMinDeterminingAxisAngleDeg, &explanation);
  EXPECT_NE(explanation.find("largest median angle from parallel 0 degrees"),
            std::string::npos)
      << explanation;
}

TEST(PrincipalAxesAreParallel, ThresholdSeparatesTheTwoConcepts) {
  std::string explanation;
  // 8 degrees from (anti-)parallel: framesets determined, but diagnosed as
  // parallel for the choice of method.
  for (const double yaw_deg : {8.0, 172.0}) {
    SCOPED_TRACE(yaw_deg);
    EXPECT_FALSE(
        PairIsParallel(yaw_deg, kMinDeterminingAxisAngleDeg, &explanation));
    EXPECT_TRUE(
        PairIsParallel(yaw_deg, kParallelAxesMaxAngleDeg, &explanation));
  }
  for (const double yaw_deg : {12.0, 30.0, 90.0, 150.0, 168.0}) {
    SCOPED_TRACE(yaw_deg);
    EXPECT_FALSE(
        PairIsParallel(yaw_deg, kParallelAxesMaxAngleDeg, &explanation));
    EXPECT_NE(explanation.find("not parallel"), std::string::npos)
        << explanation;
  }
}

// The per-pair statistic is the median: a minority of framesets with a wrong
// per-image pose (random rotation; here about a fifth) changes neither
// verdict, where the mean or the largest angle would.
TEST(PrincipalAxesAreParallel, MedianIgnoresWrongPoses) {
  for (const double yaw_deg : {0.0, 180.0, 40.0}) {
    SCOPED_TRACE(yaw_deg);
    const RadialRigScene scene = MakePairScene(yaw_deg, 0.1);
    ASSERT_GE(std::count(scene.garbage.begin(), scene.garbage.end(), 1), 4);
    std::string explanation;
    EXPECT_EQ(PrincipalAxesAreParallel(scene.dataset, scene.input,
                                       kParallelAxesMaxAngleDeg, &explanation),
              yaw_deg != 40.0)
        << explanation;
  }
}

TEST(PrincipalAxesAreParallel, RingIsNotParallel) {
  RadialRigSceneOptions options;
  options.min_cameras_per_frameset = 2;
  options.max_cameras_per_frameset = 3;
  const RadialRigScene scene = MakeRadialRigScene(options);
  std::string explanation;
  EXPECT_FALSE(PrincipalAxesAreParallel(
      scene.dataset, scene.input, kParallelAxesMaxAngleDeg, &explanation));
  // Neighbours on the ring are 72 degrees apart, opposite ones 144 (36 from
  // anti-parallel): the widest pair is a neighbouring one.
  EXPECT_NE(explanation.find("not parallel (largest median angle from "
                             "parallel 7"),
            std::string::npos)
      << explanation;
}

TEST(PrincipalAxesAreParallel, NoPairOfLocalizedImages) {
  RadialRigScene scene = MakeRadialRigScene(RadialRigSceneOptions());
  for (size_t k = 0; k < scene.dataset.images.size(); ++k) {
    if (scene.dataset.images[k].camera_index != 0) {
      scene.input.images[k].single_image_cam_from_world.reset();
    }
  }
  std::string explanation;
  EXPECT_FALSE(PrincipalAxesAreParallel(
      scene.dataset, scene.input, kParallelAxesMaxAngleDeg, &explanation));
  EXPECT_NE(explanation.find("cannot be compared"), std::string::npos)
      << explanation;
}

TEST(NormalizeRadialRigOrigin, KeepsRadialProjectionsAndIsIdempotent) {
  const RadialRigScene scene = MakeRadialRigScene(RadialRigSceneOptions());
  RigCalibration normalized = scene.truth;
  NormalizeRadialRigOrigin(0, &normalized);
  for (const RigImage& image : scene.dataset.images) {
    const Eigen::Matrix<double, 3, 4> before =
        scene.truth.CamFromWorld(image.camera_index, image.frameset_index)
            .ToMatrix();
    const Eigen::Matrix<double, 3, 4> after =
        normalized.CamFromWorld(image.camera_index, image.frameset_index)
            .ToMatrix();
    EXPECT_LT((before.topRows<2>() - after.topRows<2>()).norm(), 1e-12);
  }
  // The origin is already the point of the reference axis closest to the
  // other axes: sum_i g_i . t_i,xy = 0.
  double moment = 0;
  for (int i = 1; i < 5; ++i) {
    const Rigid3d& cam_from_rig = normalized.cam_from_rig[i];
    EXPECT_EQ(cam_from_rig.translation.z(), 0);
    moment += cam_from_rig.RotationMatrix().col(2).head<2>().dot(
        cam_from_rig.translation.head<2>());
  }
  EXPECT_LT(std::abs(moment), 1e-12);
  RigCalibration twice = normalized;
  NormalizeRadialRigOrigin(0, &twice);
  for (int i = 0; i < 5; ++i) {
    EXPECT_LT((twice.cam_from_rig[i].translation -
               normalized.cam_from_rig[i].translation)
                  .norm(),
              1e-12);
  }
}

}  // namespace principal_axes_test
}  // namespace testing
}  // namespace rig_calibrator
