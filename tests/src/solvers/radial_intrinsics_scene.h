// Correspondences with a known answer for the tests of the camera upgrade's
// solvers and estimators: camera-frame points without tz and their images
// under a RadialIntrinsics model.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <random>
#include <vector>

#include "src/solvers/radial_intrinsics.h"

namespace rig_calibrator {
namespace testing {

constexpr double kPi = 3.14159265358979323846;

struct RadialIntrinsicsScene {
  std::vector<Eigen::Vector2d> x;           // relative to the principal point
  std::vector<Eigen::Vector3d> points_cam;  // without tz
};

inline RadialIntrinsics MakeRadialIntrinsics(const RadialProfile profile,
                                             const int num_terms,
                                             const double tz,
                                             const double focal,
                                             const double k1, const double k2) {
  RadialIntrinsics model;
  model.profile = profile;
  model.num_radial_terms = num_terms;
  model.tz = tz;
  model.focal = focal;
  model.k[0] = num_terms > 0 ? k1 : 0;
  model.k[1] = num_terms > 1 ? k2 : 0;
  return model;
}

// The image of a camera-frame point at depth c + tz = `depth` on a ray at
// `angle` (radians) from the optical axis and `azimuth` around it, computed
// from the profile's formula, not from RadialIntrinsics::Project.
inline void AddPoint(const RadialIntrinsics& model, const double angle,
                     const double azimuth, const double depth,
                     RadialIntrinsicsScene* scene) {
  const double phi =
      model.profile == RadialProfile::kPolynomial ? std::tan(angle) : angle;
  const double radius =
      model.focal * phi *
      (1 + model.k[0] * phi * phi + model.k[1] * phi * phi * phi * phi);
  const Eigen::Vector2d direction(std::cos(azimuth), std::sin(azimuth));
  scene->x.push_back(radius * direction);
  const Eigen::Vector2d lateral = depth * std::tan(angle) * direction;
  scene->points_cam.emplace_back(lateral.x(), lateral.y(), depth - model.tz);
}

// `num_points` points on rays uniformly distributed in the cone of
// `max_angle_deg` around the optical axis, at 2-10 m from the camera center.
inline RadialIntrinsicsScene MakeRadialIntrinsicsScene(
    const RadialIntrinsics& model, const int num_points,
    const double max_angle_deg, const unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> uniform(0, 1);
  const double min_cos = std::cos(max_angle_deg * kPi / 180);
  RadialIntrinsicsScene scene;
  for (int i = 0; i < num_points; ++i) {
    const double angle =
        std::acos(min_cos + (1 - min_cos) * uniform(generator));
    const double azimuth = 2 * kPi * uniform(generator);
    const double distance = 2 + 8 * uniform(generator);
    AddPoint(model, angle, azimuth, distance * std::cos(angle), &scene);
  }
  return scene;
}

// Gaussian noise of `noise_px` per coordinate on every image point, and every
// point with probability `outlier_ratio` moved 20-200 px in a random
// direction (an outlier). Returns the outlier mask.
inline std::vector<char> AddNoiseAndOutliers(const double noise_px,
                                             const double outlier_ratio,
                                             const unsigned seed,
                                             RadialIntrinsicsScene* scene) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> uniform(0, 1);
  std::normal_distribution<double> noise(0, noise_px);
  std::vector<char> is_outlier;
  for (Eigen::Vector2d& x : scene->x) {
    is_outlier.push_back(uniform(generator) < outlier_ratio);
    if (is_outlier.back()) {
      const double angle = 2 * kPi * uniform(generator);
      x += (20 + 180 * uniform(generator)) *
           Eigen::Vector2d(std::cos(angle), std::sin(angle));
    } else {
      x += Eigen::Vector2d(noise(generator), noise(generator));
    }
  }
  return is_outlier;
}

// Largest error of `estimate`: tz relative to `depth_scale`, focal relative,
// distortion terms absolute (they are dimensionless and of order 0.1).
inline double RelativeError(const RadialIntrinsics& estimate,
                            const RadialIntrinsics& truth,
                            const double depth_scale) {
  return std::max({std::abs(estimate.tz - truth.tz) / depth_scale,
                   std::abs(estimate.focal - truth.focal) / truth.focal,
                   std::abs(estimate.k[0] - truth.k[0]),
                   std::abs(estimate.k[1] - truth.k[1])});
}

}  // namespace testing
}  // namespace rig_calibrator
