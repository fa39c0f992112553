#include "src/solvers/intrinsics_solvers.h"

#include <colmap/base/camera_models.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace rig_calibrator {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Camera-frame points without tz (the unknown `tz` is subtracted) on rays
// within `max_angle_deg` of the optical axis at 2-10 m, and their images
// relative to the principal point under `model`.
struct Points {
  std::vector<Eigen::Vector2d> x;
  std::vector<Eigen::Vector3d> points_cam;
};

Points MakePoints(const RadialIntrinsics& model, const int num_points,
                  const double max_angle_deg, const unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> uniform(0, 1);
  const double min_cos = std::cos(max_angle_deg * kPi / 180);
  Points points;
  for (int i = 0; i < num_points; ++i) {
    const double cos_theta = min_cos + (1 - min_cos) * uniform(generator);
    const double sin_theta = std::sqrt(1 - cos_theta * cos_theta);
    const double phi = 2 * kPi * uniform(generator);
    const double distance = 2 + 8 * uniform(generator);
    Eigen::Vector3d point_cam =
        distance * Eigen::Vector3d(sin_theta * std::cos(phi),
                                   sin_theta * std::sin(phi), cos_theta);
    point_cam.z() -= model.tz;
    Eigen::Vector2d x;
    EXPECT_TRUE(model.Project(point_cam, &x));
    points.x.push_back(x);
    points.points_cam.push_back(point_cam);
  }
  return points;
}

RadialIntrinsics MakeModel(const RadialProfile profile, const int num_terms,
                           const double tz, const double focal, const double k1,
                           const double k2) {
  RadialIntrinsics model;
  model.profile = profile;
  model.num_radial_terms = num_terms;
  model.tz = tz;
  model.focal = focal;
  model.k[0] = num_terms > 0 ? k1 : 0;
  model.k[1] = num_terms > 1 ? k2 : 0;
  return model;
}

void ExpectNear(const RadialIntrinsics& estimate, const RadialIntrinsics& truth,
                const double tolerance) {
  EXPECT_NEAR(estimate.tz, truth.tz, tolerance * std::abs(truth.tz));
  EXPECT_NEAR(estimate.focal, truth.focal, tolerance * truth.focal);
  EXPECT_NEAR(estimate.k[0], truth.k[0], tolerance);
  EXPECT_NEAR(estimate.k[1], truth.k[1], tolerance);
}

// The projection agrees with COLMAP's models whose radial part it is.
TEST(RadialIntrinsics, ProjectMatchesColmapModels) {
  const RadialIntrinsics polynomial =
      MakeModel(RadialProfile::kPolynomial, 2, 0.7, 500, -0.3, 0.08);
  const RadialIntrinsics equidistant =
      MakeModel(RadialProfile::kEquidistant, 2, 0.7, 300, 0.03, -0.005);
  const std::vector<double> radial_params = {500, 0, 0, -0.3, 0.08};
  const std::vector<double> fisheye_params = {300, 0, 0, 0.03, -0.005};
  for (const Eigen::Vector3d& point_cam :
       {Eigen::Vector3d(1, -2, 4), Eigen::Vector3d(-3, 0.5, 1.2),
        Eigen::Vector3d(1e-12, 0, 3)}) {
    const double depth = point_cam.z() + 0.7;
    Eigen::Vector2d x, expected;
    ASSERT_TRUE(polynomial.Project(point_cam, &x));
    colmap::CameraModelWorldToImage(colmap::RadialCameraModel::kModelId,
                                    radial_params, point_cam.x() / depth,
                                    point_cam.y() / depth, &expected.x(),
                                    &expected.y());
    EXPECT_LT((x - expected).norm(), 1e-9);
    ASSERT_TRUE(equidistant.Project(point_cam, &x));
    colmap::CameraModelWorldToImage(colmap::RadialFisheyeCameraModel::kModelId,
                                    fisheye_params, point_cam.x() / depth,
                                    point_cam.y() / depth, &expected.x(),
                                    &expected.y());
    EXPECT_LT((x - expected).norm(), 1e-9);
  }
  Eigen::Vector2d x;
  EXPECT_FALSE(polynomial.Project(Eigen::Vector3d(1, 1, -0.7), &x));
}

TEST(DivisionIntrinsics, MinimalAndOverdeterminedExactData) {
  // Data from the division model itself: pick the distorted pixel, undistort
  // it, and place the 3D point on the undistorted ray at depth 2-10.
  const double focal = 450, tz = -0.8, kappa1 = -4e-7, kappa2 = 2e-13;
  std::mt19937 generator(3);
  std::uniform_real_distribution<double> uniform(-300, 300);
  for (int num_kappa = 0; num_kappa <= 2; ++num_kappa) {
    SCOPED_TRACE(num_kappa);
    for (const int num_points : {num_kappa + 2, 50}) {
      std::vector<Eigen::Vector2d> x;
      std::vector<Eigen::Vector3d> points_cam;
      for (int i = 0; i < num_points; ++i) {
        const Eigen::Vector2d pixel(uniform(generator), uniform(generator));
        const double rho2 = pixel.squaredNorm();
        const double k1 = num_kappa > 0 ? kappa1 : 0;
        const double k2 = num_kappa > 1 ? kappa2 : 0;
        const Eigen::Vector2d undistorted =
            pixel / (1 + k1 * rho2 + k2 * rho2 * rho2);
        const double depth = 2 + (uniform(generator) + 300) / 75;
        x.push_back(pixel);
        points_cam.emplace_back(depth * undistorted.x() / focal,
                                depth * undistorted.y() / focal, depth - tz);
      }
      DivisionIntrinsics model;
      ASSERT_TRUE(SolveDivisionIntrinsics(x, points_cam, num_kappa, &model));
      EXPECT_NEAR(model.focal, focal, 1e-9 * focal);
      EXPECT_NEAR(model.tz, tz, 1e-9);
      EXPECT_NEAR(model.kappa[0], num_kappa > 0 ? kappa1 : 0, 1e-9 * 4e-7);
      EXPECT_NEAR(model.kappa[1], num_kappa > 1 ? kappa2 : 0, 1e-9 * 2e-13);
    }
  }
}

TEST(DivisionIntrinsics, RejectsBadInput) {
  DivisionIntrinsics model;
  const std::vector<Eigen::Vector2d> x = {Eigen::Vector2d(10, 0),
                                          Eigen::Vector2d(20, 0)};
  // Too few points for two unknowns plus one distortion term.
  EXPECT_FALSE(SolveDivisionIntrinsics(
      x, {Eigen::Vector3d(0.1, 0, 5), Eigen::Vector3d(0.2, 0, 5)}, 1, &model));
  // Points on the wrong half-line need f < 0.
  EXPECT_FALSE(SolveDivisionIntrinsics(
      x, {Eigen::Vector3d(-0.1, 0, 5), Eigen::Vector3d(-0.4, 0, 7)}, 0,
      &model));
  // All pixels on the principal point: no radial information.
  EXPECT_FALSE(SolveDivisionIntrinsics(
      {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()},
      {Eigen::Vector3d(0.1, 0, 5), Eigen::Vector3d(0.2, 0, 5)}, 0, &model));
}

TEST(FitRadialProfile, ExactAtTheTrueTz) {
  for (const RadialProfile profile :
       {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
    const RadialIntrinsics truth =
        profile == RadialProfile::kPolynomial
            ? MakeModel(profile, 2, 1.3, 500, -0.3, 0.08)
            : MakeModel(profile, 2, 1.3, 300, 0.03, -0.005);
    const Points points = MakePoints(truth, 100, 60, 5);
    RadialIntrinsics model = truth;
    model.focal = 1;
    model.k[0] = model.k[1] = 0;
    double squared_error = -1;
    ASSERT_TRUE(
        FitRadialProfile(points.x, points.points_cam, &model, &squared_error));
    ExpectNear(model, truth, 1e-10);
    EXPECT_LT(squared_error, 1e-16);
    // Any other tz fits worse.
    model.tz = truth.tz + 0.1;
    ASSERT_TRUE(
        FitRadialProfile(points.x, points.points_cam, &model, &squared_error));
    EXPECT_GT(squared_error, 1);
    // Points behind the camera.
    model.tz = -100;
    EXPECT_FALSE(
        FitRadialProfile(points.x, points.points_cam, &model, &squared_error));
  }
}

// Exact data of each profile and number of terms. A minimal sample can have
// several solutions, two of which may fall between neighbouring grid points,
// so the truth is among the candidates for most (measured: 94-100%) but not
// all samples; an overdetermined set gives the truth first.
TEST(EstimateRadialIntrinsics, ExactDataMinimalAndOverdetermined) {
  constexpr int kNumTrials = 50;
  for (const RadialProfile profile :
       {RadialProfile::kPolynomial, RadialProfile::kEquidistant}) {
    for (int num_terms = 0; num_terms <= 2; ++num_terms) {
      SCOPED_TRACE(10 * static_cast<int>(profile) + num_terms);
      const RadialIntrinsics truth =
          profile == RadialProfile::kPolynomial
              ? MakeModel(profile, num_terms, -0.6, 500, -0.3, 0.08)
              : MakeModel(profile, num_terms, -0.6, 300, 0.03, -0.005);
      // Within 45 degrees r_d = f q (1 - 0.3 q^2) still grows with q.
      const double max_angle_deg =
          profile == RadialProfile::kPolynomial ? 45 : 75;
      int num_found = 0;
      for (int trial = 0; trial < kNumTrials; ++trial) {
        const Points minimal =
            MakePoints(truth, num_terms + 2, max_angle_deg, 100 + trial);
        const std::vector<RadialIntrinsics> candidates =
            EstimateRadialIntrinsics(minimal.x, minimal.points_cam, profile,
                                     num_terms);
        EXPECT_LE(candidates.size(), 3);
        for (const RadialIntrinsics& candidate : candidates) {
          if (std::abs(candidate.tz - truth.tz) < 1e-7 &&
              std::abs(candidate.focal - truth.focal) < 1e-7 * truth.focal &&
              std::abs(candidate.k[0] - truth.k[0]) < 1e-7 &&
              std::abs(candidate.k[1] - truth.k[1]) < 1e-7) {
            ++num_found;
            break;
          }
        }
      }
      EXPECT_GE(num_found, kNumTrials * 9 / 10);

      const Points points = MakePoints(truth, 200, max_angle_deg, 20);
      const std::vector<RadialIntrinsics> models = EstimateRadialIntrinsics(
          points.x, points.points_cam, profile, num_terms);
      ASSERT_FALSE(models.empty());
      ExpectNear(models[0], truth, 1e-8);
    }
  }
}

// Minimal samples of points on the wrong half-line of the radial pose fit
// profiles whose radial factor turns negative, i.e. that mirror the points
// through the principal point; such profiles are rejected.
TEST(EstimateRadialIntrinsics, RejectsMirroringProfiles) {
  const RadialIntrinsics truth =
      MakeModel(RadialProfile::kPolynomial, 2, 0.4, 500, -0.3, 0.08);
  int num_estimates = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Points points = MakePoints(truth, 4, 45, 200 + trial);
    num_estimates += !EstimateRadialIntrinsics(points.x, points.points_cam,
                                               RadialProfile::kPolynomial, 2)
                          .empty();
    for (Eigen::Vector3d& point : points.points_cam) {
      point.head<2>() *= -1;
    }
    EXPECT_TRUE(EstimateRadialIntrinsics(points.x, points.points_cam,
                                         RadialProfile::kPolynomial, 2)
                    .empty());
  }
  EXPECT_EQ(num_estimates, 20);
}

TEST(EstimateRadialIntrinsics, NoisyData) {
  const RadialIntrinsics truth =
      MakeModel(RadialProfile::kPolynomial, 2, 0.4, 500, -0.3, 0.08);
  Points points = MakePoints(truth, 500, 50, 7);
  std::mt19937 generator(8);
  std::normal_distribution<double> noise(0, 0.5);
  for (Eigen::Vector2d& x : points.x) {
    x += Eigen::Vector2d(noise(generator), noise(generator));
  }
  const std::vector<RadialIntrinsics> models = EstimateRadialIntrinsics(
      points.x, points.points_cam, RadialProfile::kPolynomial, 2);
  ASSERT_FALSE(models.empty());
  EXPECT_NEAR(models[0].focal, truth.focal, 0.005 * truth.focal);
  EXPECT_NEAR(models[0].tz, truth.tz, 0.02);
  EXPECT_NEAR(models[0].k[0], truth.k[0], 0.01);
  EXPECT_NEAR(models[0].k[1], truth.k[1], 0.01);
}

TEST(RadialIntrinsicsEstimator, ResidualsAreSquaredReprojectionErrors) {
  const RadialIntrinsics truth =
      MakeModel(RadialProfile::kEquidistant, 2, 0.4, 300, 0.03, -0.005);
  Points points = MakePoints(truth, 3, 60, 9);
  points.x[1] += Eigen::Vector2d(3, -4);
  points.points_cam[2].z() = -0.5;  // behind the camera
  RadialIntrinsicsEstimator<2> estimator;
  estimator.profile = RadialProfile::kEquidistant;
  std::vector<double> residuals;
  estimator.Residuals(points.x, points.points_cam, truth, &residuals);
  ASSERT_EQ(residuals.size(), 3);
  EXPECT_LT(residuals[0], 1e-18);
  EXPECT_NEAR(residuals[1], 25, 1e-9);
  EXPECT_EQ(residuals[2], std::numeric_limits<double>::max());
}

}  // namespace
}  // namespace rig_calibrator
