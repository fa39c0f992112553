#include "src/geometry/rigid3d.h"

#include <gtest/gtest.h>

namespace rig_calibrator {
namespace rigid3d_test {

Rigid3d RandomTransform(int seed) {
  std::srand(seed);
  return Rigid3d(Eigen::Quaterniond(Eigen::Vector4d::Random()).normalized(),
                 Eigen::Vector3d::Random());
}

TEST(Rigid3d, ComposeAppliesRightThenLeft) {
  const Rigid3d a_from_b = RandomTransform(1);
  const Rigid3d b_from_c = RandomTransform(2);
  const Eigen::Vector3d x_c(0.3, -1.2, 2.5);
  EXPECT_LT(((a_from_b * b_from_c) * x_c - a_from_b * (b_from_c * x_c)).norm(),
            1e-12);
}

TEST(Rigid3d, InverseUndoes) {
  const Rigid3d a_from_b = RandomTransform(3);
  const Eigen::Vector3d x_b(1.0, 2.0, -3.0);
  EXPECT_LT((a_from_b.Inverse() * (a_from_b * x_b) - x_b).norm(), 1e-12);
  // The center of a cam_from_world transform maps to the camera origin.
  EXPECT_LT((a_from_b * a_from_b.Center()).norm(), 1e-12);
}

TEST(Rigid3d, QvecRoundTripMatchesColmapOrder) {
  const Rigid3d pose = RandomTransform(4);
  const Eigen::Vector4d qvec = pose.Qvec();
  EXPECT_DOUBLE_EQ(qvec(0), pose.rotation.w());
  const Rigid3d back = Rigid3d::FromQvecTvec(qvec, pose.translation);
  EXPECT_LT(RotationDifferenceDeg(back.rotation, pose.rotation), 1e-9);
}

TEST(Rigid3d, RotationDifferenceOfKnownAngle) {
  const Eigen::Quaterniond a = Eigen::Quaterniond::Identity();
  const Eigen::Quaterniond b(
      Eigen::AngleAxisd(0.1 * M_PI / 180.0, Eigen::Vector3d::UnitY()));
  EXPECT_NEAR(RotationDifferenceDeg(a, b), 0.1, 1e-9);
}

TEST(Rigid3d, NearestRotationOfNoisyRotation) {
  const Eigen::Matrix3d rotation = RandomTransform(5).RotationMatrix();
  const Eigen::Matrix3d noisy =
      2.0 * rotation;  // scaled: same nearest rotation
  EXPECT_LT((NearestRotation(noisy) - rotation).norm(), 1e-12);
  const Eigen::Matrix3d reflection = -rotation;  // det -1: still a rotation out
  EXPECT_NEAR(NearestRotation(reflection).determinant(), 1.0, 1e-12);
}

// Known angles, independent of the vectors' lengths, and full precision near
// 0 and pi, where acos of the normalized dot product loses half the digits
// (acos(1 - 5e-21) rounds to 0).
TEST(AngleBetweenRad, KnownAnglesAtFullPrecision) {
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  EXPECT_NEAR(AngleBetweenRad(x, Eigen::Vector3d(1, 1, 0)), M_PI / 4, 1e-15);
  EXPECT_NEAR(AngleBetweenRad(3 * x, Eigen::Vector3d(0, 0, 0.2)), M_PI / 2,
              1e-15);
  EXPECT_NEAR(AngleBetweenRad(Eigen::Vector3d(1e-3, 1e-3, 0), 1e3 * x),
              M_PI / 4, 1e-15);
  for (const double angle : {1e-10, 1e-6, 0.3}) {
    const Eigen::Vector3d y(std::cos(angle), std::sin(angle), 0);
    EXPECT_NEAR(AngleBetweenRad(x, y), angle, 1e-15 * angle) << angle;
    EXPECT_NEAR(AngleBetweenRad(x, -y), M_PI - angle, 1e-15) << angle;
  }
  EXPECT_EQ(AngleBetweenRad(x, x), 0);
  EXPECT_EQ(AngleBetweenRad(x, -x), M_PI);
  EXPECT_EQ(AngleBetweenRad(x, Eigen::Vector3d::Zero()), 0);
}

TEST(Rigid3d, AngleAxisTranslationRoundTrip) {
  const Rigid3d pose = RandomTransform(7);
  const std::array<double, 6> parameters = ToAngleAxisTranslation(pose);
  const Eigen::Vector3d angle_axis(parameters[0], parameters[1], parameters[2]);
  EXPECT_NEAR(angle_axis.norm(), Eigen::AngleAxisd(pose.rotation).angle(),
              1e-12);
  const Rigid3d back = FromAngleAxisTranslation(parameters);
  EXPECT_LT(RotationDifferenceDeg(back.rotation, pose.rotation), 1e-9);
  EXPECT_LT((back.translation - pose.translation).norm(), 1e-15);
}

}  // namespace rigid3d_test
}  // namespace rig_calibrator
