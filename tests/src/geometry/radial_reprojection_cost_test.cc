#include "src/geometry/radial_reprojection_cost.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <memory>
#include <random>

#include "src/geometry/radial_error.h"

namespace rig_calibrator {
namespace radial_reprojection_cost_test {

// Residual of the cost function at a pose, with its Jacobians.
struct Evaluation {
  Eigen::Vector2d residual;
  double jacobian_rotation[8];
  double jacobian_translation[6];
};

Evaluation Evaluate(const Rigid3d& pose, const Eigen::Vector2d& x,
                    const Eigen::Vector3d& X) {
  const double rotation[4] = {pose.rotation.w(), pose.rotation.x(),
                              pose.rotation.y(), pose.rotation.z()};
  const double* parameters[2] = {rotation, pose.translation.data()};
  const std::unique_ptr<ceres::CostFunction> cost(
      RadialReprojectionCost::Create(x, X));
  Evaluation evaluation;
  double* jacobians[2] = {evaluation.jacobian_rotation,
                          evaluation.jacobian_translation};
  EXPECT_TRUE(
      cost->Evaluate(parameters, evaluation.residual.data(), jacobians));
  return evaluation;
}

// |e| is the radial error of radial_error.h under the pose (rotation and
// translation applied to X) on the correct half-line, and e = x without pull
// on the pose on the wrong one; tz never matters.
TEST(RadialReprojectionCost, IsTheRadialErrorUnderThePose) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> uniform(-1, 1);
  int num_wrong_side = 0;
  for (int k = 0; k < 200; ++k) {
    const Rigid3d pose(
        Eigen::Quaterniond(uniform(rng), uniform(rng), uniform(rng),
                           uniform(rng))
            .normalized(),
        Eigen::Vector3d(uniform(rng), uniform(rng), 2 * uniform(rng)));
    const Eigen::Vector3d X(5 * uniform(rng), 5 * uniform(rng),
                            5 * uniform(rng));
    const Eigen::Vector2d x(300 * uniform(rng), 300 * uniform(rng));
    const Evaluation evaluation = Evaluate(pose, x, X);
    EXPECT_EQ(evaluation.jacobian_translation[2], 0);
    EXPECT_EQ(evaluation.jacobian_translation[5], 0);
    const double error = RadialReprojectionError(pose, x, X);
    if (std::isfinite(error)) {
      EXPECT_NEAR(evaluation.residual.norm(), error, 1e-9 * (1 + error)) << k;
      // e is perpendicular to the predicted direction.
      const Eigen::Vector2d direction = (pose * X).head<2>().normalized();
      EXPECT_NEAR(evaluation.residual.dot(direction), 0, 1e-9) << k;
      // d e / d(tx, ty) = -(z x^T + alpha I)(I - z z^T) / n is not zero.
      EXPECT_NE(evaluation.jacobian_translation[0], 0) << k;
    } else {
      ++num_wrong_side;
      EXPECT_EQ(evaluation.residual, x) << k;
      for (const double value : evaluation.jacobian_rotation) {
        EXPECT_EQ(value, 0);
      }
      for (const double value : evaluation.jacobian_translation) {
        EXPECT_EQ(value, 0);
      }
    }
  }
  EXPECT_GT(num_wrong_side, 50);
  EXPECT_LT(num_wrong_side, 150);
}

// A point that the pose puts on the optical axis: e = x, at any map scale
// (tz takes part in the test of radial_error.h's IsOnOpticalAxis).
TEST(RadialReprojectionCost, OnTheOpticalAxisIsX) {
  const Eigen::Vector2d x(3, 4);
  for (const double scale : {1e-3, 1.0, 1e3}) {
    const Rigid3d pose(Eigen::Quaterniond::Identity(),
                       Eigen::Vector3d(-scale, 0, scale));
    const Evaluation evaluation =
        Evaluate(pose, x, Eigen::Vector3d(scale, 1e-13 * scale, 4 * scale));
    EXPECT_EQ(evaluation.residual, x) << scale;
  }
}

}  // namespace radial_reprojection_cost_test
}  // namespace rig_calibrator
