#include "src/geometry/radial_error.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>

#include "src/geometry/radial_residual.h"

namespace rig_calibrator {
namespace radial_error_test {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Distance from x to the half-line {s d : s >= 0}, computed from the angle
// phi between x and d instead of by projection: |x| sin(phi) if phi < 90
// degrees, else |x| (the nearest point is the end, the origin).
double DistanceToHalfLine(const Eigen::Vector2d& x, const Eigen::Vector2d& d) {
  const double phi = std::abs(
      std::atan2(d.x() * x.y() - d.y() * x.x(), d.x() * x.x() + d.y() * x.y()));
  return phi < M_PI / 2 ? x.norm() * std::sin(phi) : x.norm();
}

// A camera-frame point `angle` radians off the optical axis, at `depth`,
// in the direction `azimuth` of the image plane.
Eigen::Vector3d PointOffAxis(double angle, double azimuth, double depth) {
  return depth * Eigen::Vector3d(std::sin(angle) * std::cos(azimuth),
                                 std::sin(angle) * std::sin(azimuth),
                                 std::cos(angle));
}

// On the correct half-line the squared error is the squared distance to the
// line; on the wrong one (and at 90 degrees) +infinity. The depth, the
// focal length (the scale of x) and the sign of Y_3 do not matter.
TEST(SquaredRadialErrorInCamera, IsTheSquaredDistanceToTheHalfLine) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> uniform(-1, 1);
  int num_wrong_side = 0;
  for (int k = 0; k < 1000; ++k) {
    const Eigen::Vector3d Y(5 * uniform(rng), 5 * uniform(rng),
                            10 * uniform(rng));
    const Eigen::Vector2d x(400 * uniform(rng), 400 * uniform(rng));
    const double expected = DistanceToHalfLine(x, Y.head<2>());
    const bool correct_side = x.dot(Y.head<2>()) > 0;
    const double error_sq = SquaredRadialErrorInCamera(Y, x);
    if (correct_side) {
      EXPECT_NEAR(std::sqrt(error_sq), expected, 1e-9 * (1 + expected)) << k;
      // Scaling Y (the depth) or x (the focal length) by a positive factor:
      // the error scales with x only.
      EXPECT_NEAR(SquaredRadialErrorInCamera(0.37 * Y, 2.5 * x),
                  6.25 * error_sq, 1e-9 * (1 + 6.25 * error_sq));
    } else {
      EXPECT_EQ(error_sq, kInf) << k;
      ++num_wrong_side;
    }
  }
  EXPECT_GT(num_wrong_side, 300);
  EXPECT_LT(num_wrong_side, 700);
  // Hand-computed: direction (1, 0); x = (100, 3) is 3 from the line.
  const Eigen::Vector3d Y(2, 0, 5);
  EXPECT_NEAR(SquaredRadialErrorInCamera(Y, Eigen::Vector2d(100, 3)), 9, 1e-12);
  EXPECT_EQ(SquaredRadialErrorInCamera(Y, Eigen::Vector2d(250, 0)), 0);
  EXPECT_EQ(SquaredRadialErrorInCamera(Y, Eigen::Vector2d(-100, 3)), kInf);
  // Perpendicular to the direction, and the principal point itself.
  EXPECT_EQ(SquaredRadialErrorInCamera(Y, Eigen::Vector2d(0, 3)), kInf);
  EXPECT_EQ(SquaredRadialErrorInCamera(Y, Eigen::Vector2d(0, 0)), kInf);
}

TEST(SquaredRadialErrorInCamera, NonFiniteInputGivesInfinity) {
  const Eigen::Vector3d Y(2, 1, 5);
  const Eigen::Vector2d x(100, 30);
  EXPECT_EQ(SquaredRadialErrorInCamera(Y, Eigen::Vector2d(kNaN, 30)), kInf);
  EXPECT_EQ(SquaredRadialErrorInCamera(Y, Eigen::Vector2d(kInf, 30)), kInf);
  EXPECT_EQ(SquaredRadialErrorInCamera(Y, Eigen::Vector2d(100, kInf)), kInf);
  EXPECT_EQ(SquaredRadialErrorInCamera(Eigen::Vector3d(kNaN, 1, 5), x), kInf);
  EXPECT_EQ(SquaredRadialErrorInCamera(Eigen::Vector3d(2, 1, kNaN), x), kInf);
  EXPECT_EQ(SquaredRadialErrorInCamera(Eigen::Vector3d(kInf, 1, 5), x), kInf);
  EXPECT_EQ(SquaredRadialErrorInCamera(Eigen::Vector3d(2, 1, kInf), x), kInf);
}

// RadialReprojectionError applies cam_from_world, rotation and translation,
// before the camera-frame error.
TEST(RadialReprojectionError, TransformsThePointFirst) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> uniform(-1, 1);
  for (int k = 0; k < 100; ++k) {
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(
            M_PI * uniform(rng),
            Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng))
                .normalized())
            .toRotationMatrix();
    const Eigen::Vector3d translation(uniform(rng), uniform(rng), 0);
    const Eigen::Vector3d X(5 * uniform(rng), 5 * uniform(rng),
                            5 * uniform(rng));
    const Eigen::Vector2d x(300 * uniform(rng), 300 * uniform(rng));
    const Eigen::Vector3d Y = rotation * X + translation;
    const double error =
        RadialReprojectionError(Rigid3d(rotation, translation), x, X);
    if (x.dot(Y.head<2>()) > 0) {
      EXPECT_NEAR(error, DistanceToHalfLine(x, Y.head<2>()), 1e-9) << k;
    } else {
      EXPECT_EQ(error, kInf) << k;
    }
  }
  // t moves (2, -3, 5) to (3, 0, 5): direction (1, 0), x = (100, 5) is 5 off.
  const Rigid3d shifted(Eigen::Quaterniond::Identity(),
                        Eigen::Vector3d(1, 3, 0));
  EXPECT_NEAR(RadialReprojectionError(shifted, Eigen::Vector2d(100, 5),
                                      Eigen::Vector3d(2, -3, 5)),
              5, 1e-12);
}

// The optical-axis test is relative: points up to 1e-12 rad off the axis
// are on it, points 1e-11 rad off are not, at every map scale; an absolute
// threshold on |Y_12| would call the 1e-11 rad point of a map in kilometers
// (scale 1e-3, |Y_12| ~ 5e-14) on-axis and the 1e-13 rad point of a map in
// millimeters (scale 1e3, |Y_12| ~ 5e-10) off-axis.
TEST(IsOnOpticalAxis, IsTheSameAtEveryMapScale) {
  const Eigen::Vector2d x(30, 40);
  for (const double scale : {1e-3, 1.0, 1e3}) {
    SCOPED_TRACE("scale " + std::to_string(scale));
    for (const double depth : {5.0, -5.0}) {
      for (const double angle : {0.0, 1e-13, 5e-13}) {
        const Eigen::Vector3d Y = PointOffAxis(angle, 0.9, scale * depth);
        EXPECT_TRUE(IsOnOpticalAxis(Y)) << angle;
        EXPECT_EQ(SquaredRadialErrorInCamera(Y, x), kInf) << angle;
        double residual[2];
        RadialResidual(x.data(), Y.data(), residual);
        EXPECT_EQ(residual[0], x.x());
        EXPECT_EQ(residual[1], x.y());
      }
      for (const double angle : {1e-11, 1e-9, 0.3}) {
        // Y_12 along (3, 4) (the azimuth turns with the sign of the depth):
        // x lies on the predicted half-line.
        const double azimuth = std::atan2(4.0, 3.0) + (depth > 0 ? 0 : M_PI);
        const Eigen::Vector3d Y = PointOffAxis(angle, azimuth, scale * depth);
        EXPECT_FALSE(IsOnOpticalAxis(Y)) << angle;
        EXPECT_NEAR(SquaredRadialErrorInCamera(Y, x), 0, 1e-18) << angle;
        double residual[2];
        RadialResidual(x.data(), Y.data(), residual);
        EXPECT_NEAR(residual[0], 0, 1e-9) << angle;
        EXPECT_NEAR(residual[1], 0, 1e-9) << angle;
      }
    }
  }
  EXPECT_TRUE(IsOnOpticalAxis(Eigen::Vector3d(0, 0, 0)));
  EXPECT_TRUE(IsOnOpticalAxis(Eigen::Vector3d(kNaN, 1, 5)));
  EXPECT_TRUE(IsOnOpticalAxis(Eigen::Vector3d(1, 1, kNaN)));
  EXPECT_FALSE(IsOnOpticalAxis(Eigen::Vector3d(1, 0, 0)));
}

// |RadialResidual| is the distance to the half-line everywhere off the axis:
// the radial error on the correct side, the distance to the half-line's end
// (|x|) on the wrong side, continuous across alpha = 0.
TEST(RadialResidual, NormIsTheDistanceToTheHalfLine) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(-1, 1);
  for (int k = 0; k < 1000; ++k) {
    const Eigen::Vector3d Y(5 * uniform(rng), 5 * uniform(rng),
                            10 * uniform(rng));
    const Eigen::Vector2d x(400 * uniform(rng), 400 * uniform(rng));
    Eigen::Vector2d residual;
    RadialResidual(x.data(), Y.data(), residual.data());
    EXPECT_NEAR(residual.norm(), DistanceToHalfLine(x, Y.head<2>()),
                1e-9 * (1 + x.norm()))
        << k;
    if (x.dot(Y.head<2>()) > 0) {
      // e = x - alpha z is perpendicular to the direction, and its squared
      // norm is the squared radial error.
      EXPECT_NEAR(residual.dot(Y.head<2>().normalized()), 0, 1e-9);
      EXPECT_NEAR(residual.squaredNorm(), SquaredRadialErrorInCamera(Y, x),
                  1e-9 * (1 + residual.squaredNorm()));
    } else {
      EXPECT_EQ(residual, x);
    }
  }
}

}  // namespace radial_error_test
}  // namespace rig_calibrator
