// CheckModelValidity on exact models: valid pinhole-type and fisheye models,
// a folding OPENCV (strong negative k2) and a folding OPENCV fitted to a
// 150-degree fisheye lens. AddResidualProfileCheck on residual profiles
// with and without a systematic radial misfit: the verdict, the suggested
// model by lens width and kind, and the message.
#include "src/calibration/model_validity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "tests/testing.h"

namespace rig_calibrator {
namespace model_validity_test {

using testing::MakeCamera;

void Print(const std::string& what, const ModelValidity& validity) {
  std::cout << what << ": valid " << validity.valid << ", monotonic "
            << validity.monotonic << ", round trip "
            << validity.max_roundtrip_error_px << " px, fold radius "
            << (validity.fold_radius_px ? *validity.fold_radius_px : -1)
            << " px, corner radius " << validity.corner_radius_px
            << " px: " << validity.message << std::endl;
}

TEST(ModelValidity, RingOpenCVCameraIsValid) {
  // ring5's first camera (src/synthetic/rig_presets.cc).
  const ModelValidity validity = CheckModelValidity(MakeCamera(
      "OPENCV", 640, 480, {420, 421, 332, 232, -0.30, 0.080, 4e-4, -3e-4}));
  Print("ring5 OPENCV", validity);
  EXPECT_TRUE(validity.valid);
  EXPECT_TRUE(validity.monotonic);
  EXPECT_LT(validity.max_roundtrip_error_px, 1e-6);
  EXPECT_FALSE(validity.fold_radius_px.has_value());
  EXPECT_NEAR(validity.corner_radius_px, std::hypot(332, 248), 1e-9);
  EXPECT_TRUE(validity.suggested_model.empty());
}

TEST(ModelValidity, PinholeAndRadialModelsAreValid) {
  for (const colmap::Camera& camera :
       {MakeCamera("SIMPLE_PINHOLE", 640, 480, {500, 320, 240}),
        MakeCamera("PINHOLE", 640, 480, {500, 510, 300, 250}),
        MakeCamera("SIMPLE_RADIAL", 640, 480, {500, 320, 240, -0.1}),
        MakeCamera("RADIAL", 640, 480, {380, 326, 236, -0.20, 0.04})}) {
    const ModelValidity validity = CheckModelValidity(camera);
    Print(camera.ModelName(), validity);
    EXPECT_TRUE(validity.valid) << camera.ModelName();
  }
}

TEST(ModelValidity, StrongNegativeK2Folds) {
  // r_d = r (1 + k1 r^2 + k2 r^4) with k1 = 0, k2 = -0.5 peaks where
  // 1 + 5 k2 r^4 = 0: r^4 = 0.4, r = 0.795, r_d = 0.795 (1 - 0.5 * 0.4) =
  // 0.636, 318.1 px at f = 500: inside the image (corner at 400 px).
  const colmap::Camera camera =
      MakeCamera("OPENCV", 640, 480, {500, 500, 320, 240, 0, -0.5, 0, 0});
  const ModelValidity validity = CheckModelValidity(camera);
  Print("OPENCV k2 = -0.5", validity);
  EXPECT_FALSE(validity.valid);
  EXPECT_FALSE(validity.monotonic);
  ASSERT_TRUE(validity.fold_radius_px.has_value());
  const double r = std::pow(0.4, 0.25);
  const double expected_fold_px = 500 * r * (1 - 0.5 * 0.4);
  // The angle sampling (0.045 degrees) brackets the peak to well under 1 px.
  EXPECT_NEAR(*validity.fold_radius_px, expected_fold_px, 0.5);
  EXPECT_NEAR(*validity.fold_angle_deg, std::atan(r) * 180 / M_PI, 0.1);
  EXPECT_EQ(validity.corner_radius_px, 400);
  EXPECT_GT(validity.max_roundtrip_error_px, 1);
  EXPECT_EQ(validity.suggested_model, "OPENCV_FISHEYE");
  EXPECT_NE(validity.message.find("folds back at"), std::string::npos);
}

TEST(ModelValidity, FoldOutsideTheImageIsValid) {
  // The same distortion with f = 2000: the corner (400 px) is at r_d = 0.2,
  // well before the fold at r_d = 0.636.
  const ModelValidity validity = CheckModelValidity(
      MakeCamera("OPENCV", 640, 480, {2000, 2000, 320, 240, 0, -0.5, 0, 0}));
  Print("OPENCV k2 = -0.5, f = 2000", validity);
  EXPECT_TRUE(validity.valid);
}

TEST(ModelValidity, TangentialFoldIsFound) {
  // A radially monotonic model whose tangential terms are so strong that the
  // Jacobian determinant changes sign inside the image.
  const ModelValidity validity = CheckModelValidity(
      MakeCamera("OPENCV", 640, 480, {300, 300, 320, 240, 0, 0, 0.5, 0}));
  Print("OPENCV p1 = 0.5", validity);
  EXPECT_FALSE(validity.valid);
}

TEST(ModelValidity, FisheyeModelsAreValid) {
  // fisheye_helmet5's widest camera (155 degrees diagonal: f = 290.4 from
  // FisheyeFocalForDiagonalFov) and simpler fisheye models of lenses of
  // 140-160 degrees.
  for (const colmap::Camera& camera :
       {MakeCamera("OPENCV_FISHEYE", 640, 480,
                   {290.4, 290.1, 323, 248, 0.015, -0.008, 0.004, -0.0006}),
        MakeCamera("SIMPLE_RADIAL_FISHEYE", 640, 480, {300, 320, 240, 0.02}),
        MakeCamera("RADIAL_FISHEYE", 800, 600, {351, 393, 305, 0.03, -0.01}),
        MakeCamera("THIN_PRISM_FISHEYE", 640, 480,
                   {320, 320, 320, 240, 0.02, -0.01, 1e-4, -1e-4, 0.002,
                    -0.0005, 1e-4, 1e-4})}) {
    const ModelValidity validity = CheckModelValidity(camera);
    Print(camera.ModelName(), validity);
    EXPECT_TRUE(validity.valid) << camera.ModelName();
    EXPECT_LT(validity.max_roundtrip_error_px, 0.01) << camera.ModelName();
  }
}

TEST(ModelValidity, ImageBeyondTheHemisphereIsInvalid) {
  // f = 200: the corners (400 px) would be at theta_d = 2 rad, beyond 90
  // degrees, which COLMAP's models cannot project.
  const ModelValidity validity = CheckModelValidity(
      MakeCamera("SIMPLE_RADIAL_FISHEYE", 640, 480, {200, 320, 240, 0}));
  Print("SIMPLE_RADIAL_FISHEYE f = 200", validity);
  EXPECT_FALSE(validity.valid);
  EXPECT_NE(validity.message.find("90 deg"), std::string::npos);
}

TEST(ModelValidity, FoldingFisheyeModelIsInvalid) {
  // theta_d = theta (1 + k1 theta^2) with k1 = -0.3 peaks at theta^2 = 1.11
  // (60 degrees), theta_d = 0.702, 140 px at f = 200: inside the image.
  const ModelValidity validity = CheckModelValidity(
      MakeCamera("SIMPLE_RADIAL_FISHEYE", 640, 480, {200, 320, 240, -0.3}));
  Print("SIMPLE_RADIAL_FISHEYE k = -0.3", validity);
  EXPECT_FALSE(validity.valid);
  ASSERT_TRUE(validity.fold_radius_px.has_value());
  const double theta = std::sqrt(1 / 0.9);
  EXPECT_NEAR(*validity.fold_radius_px, 200 * theta * (1 - 0.3 * theta * theta),
              0.5);
  EXPECT_TRUE(validity.suggested_model.empty());
}

// The radial residual profile of 2000 observations of `camera` uniform over
// radii 5-300 px, observed with a radial bias of -0.6 px between 180 and
// 240 px (`biased`) or none, in 0.5 px noise.
RadialResidualProfile MakeProfile(const colmap::Camera& camera, bool biased) {
  const Eigen::Vector2d pp(camera.PrincipalPointX(), camera.PrincipalPointY());
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(0, 1);
  std::normal_distribution<double> noise(0, 0.5);
  std::vector<Eigen::Vector2d> observed, projected;
  for (int k = 0; k < 2000; ++k) {
    const double r = 5 + 295 * std::sqrt(unit(rng));
    const double a = 2 * M_PI * unit(rng);
    const Eigen::Vector2d direction(std::cos(a), std::sin(a));
    const double bias = biased && r > 180 && r < 240 ? -0.6 : 0.0;
    projected.push_back(pp + r * direction);
    observed.push_back(projected.back() + bias * direction +
                       Eigen::Vector2d(noise(rng), noise(rng)));
  }
  return ComputeRadialResidualProfile(pp, observed, projected);
}

TEST(ModelValidity, DataThatTheModelFitsKeepItValid) {
  const colmap::Camera camera = MakeCamera(
      "OPENCV", 640, 480, {420, 421, 332, 232, -0.30, 0.080, 4e-4, -3e-4});
  ModelValidity validity = CheckModelValidity(camera);
  AddResidualProfileCheck(camera, MakeProfile(camera, false), false, &validity);
  Print("ring5 OPENCV, unbiased residuals", validity);
  EXPECT_TRUE(validity.valid);
  EXPECT_TRUE(validity.fits_data);
  ASSERT_TRUE(validity.residual_profile.has_value());
  EXPECT_TRUE(validity.residual_profile->evaluated);
  EXPECT_TRUE(validity.suggested_model.empty());
}

TEST(ModelValidity, SystematicMisfitMakesTheModelInvalid) {
  // OPENCV as fitted to fisheye_helmet5 (f 296 px, k2 > 0: no fold): the
  // inliers' 300 px are 56 degrees off axis, a wide lens.
  const colmap::Camera wide = MakeCamera(
      "OPENCV", 640, 480, {295.8, 295.7, 325.8, 234.9, -0.233, 0.0405, 0, 0});
  ModelValidity validity = CheckModelValidity(wide);
  ASSERT_TRUE(validity.valid);
  AddResidualProfileCheck(wide, MakeProfile(wide, true), false, &validity);
  Print("OPENCV on a fisheye, biased residuals", validity);
  EXPECT_FALSE(validity.valid);
  EXPECT_FALSE(validity.fits_data);
  EXPECT_TRUE(validity.monotonic);
  EXPECT_EQ(validity.suggested_model, "OPENCV_FISHEYE");
  EXPECT_NE(validity.message.find("does not follow the lens"),
            std::string::npos);
  EXPECT_NE(validity.message.find("inwards"), std::string::npos);

  // A narrow lens (f 420 px: 300 px is 35 degrees off axis): the next model
  // with more terms.
  const colmap::Camera narrow = MakeCamera(
      "OPENCV", 640, 480, {420, 421, 332, 232, -0.30, 0.080, 4e-4, -3e-4});
  validity = CheckModelValidity(narrow);
  AddResidualProfileCheck(narrow, MakeProfile(narrow, true), false, &validity);
  Print("narrow OPENCV, biased residuals", validity);
  EXPECT_FALSE(validity.valid);
  EXPECT_EQ(validity.suggested_model, "FULL_OPENCV");

  // The same with parameters held: the misfit is recorded, the verdict on
  // the model left (the given values may be what misfits).
  validity = CheckModelValidity(narrow);
  AddResidualProfileCheck(narrow, MakeProfile(narrow, true), true, &validity);
  EXPECT_TRUE(validity.valid);
  EXPECT_FALSE(validity.fits_data);
  EXPECT_TRUE(validity.suggested_model.empty());

  // A fisheye model: the next fisheye model.
  const colmap::Camera fisheye =
      MakeCamera("RADIAL_FISHEYE", 640, 480, {300, 320, 240, 0.02, -0.003});
  validity = CheckModelValidity(fisheye);
  AddResidualProfileCheck(fisheye, MakeProfile(fisheye, true), false,
                          &validity);
  EXPECT_FALSE(validity.valid);
  EXPECT_EQ(validity.suggested_model, "OPENCV_FISHEYE");
}

TEST(ModelValidity, FoldStaysTheReasonWhenTheModelAlsoMisfits) {
  const colmap::Camera camera =
      MakeCamera("OPENCV", 640, 480, {500, 500, 320, 240, 0, -0.5, 0, 0});
  ModelValidity validity = CheckModelValidity(camera);
  const std::string fold_message = validity.message;
  AddResidualProfileCheck(camera, MakeProfile(camera, true), false, &validity);
  EXPECT_FALSE(validity.valid);
  EXPECT_FALSE(validity.fits_data);
  EXPECT_EQ(validity.message, fold_message);
  EXPECT_EQ(validity.suggested_model, "OPENCV_FISHEYE");
}

}  // namespace model_validity_test
}  // namespace rig_calibrator
