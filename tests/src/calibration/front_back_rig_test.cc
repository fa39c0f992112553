// A front/back two-camera rig, the common car and dash-cam layout: one camera
// looking forward, one backward, 0.30 m apart. For 1D radial cameras its
// anti-parallel axes are as degenerate as parallel ones (the rig's
// translation along the common axis is unobservable), so the default method
// must diagnose it and fall back to rd_ra instead of failing.
#include <colmap/util/math.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>

#include "src/calibration/pipeline.h"
#include "src/calibration/principal_axes.h"
#include "src/evaluation/evaluation.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {
namespace front_back_rig_test {

// ring5's layout with two cameras: yaw 0 and 180 degrees on the 0.15 m ring,
// pitched by 2 and -3 degrees (axes 179 degrees apart). The pipeline tests'
// hard scenario: 0.5 px noise, 30% wrong matches, 10% of the images missing.
SyntheticRig FrontBackRig() {
  SyntheticRigOptions options;
  options.preset = RigPreset::kRing5;
  options.ring_num_cameras = 2;
  options.num_framesets = 30;
  options.noise_px = 0.5;
  options.outlier_ratio = 0.3;
  options.missing_image_ratio = 0.1;
  options.seed = 7;
  return GenerateSyntheticRig(options);
}

PipelineOptions QuietDefaultOptions() {
  PipelineOptions options;
  options.print_progress = false;
  return options;
}

TEST(FrontBackRig, LayoutIsFrontAndBack) {
  const SyntheticRig rig = FrontBackRig();
  ASSERT_EQ(rig.truth.cam_from_rig.size(), 2u);
  const Rigid3d& back_from_front = rig.truth.cam_from_rig[1];
  EXPECT_NEAR(back_from_front.Inverse().translation.norm(), 0.30, 0.005);
  const double angle_deg = colmap::RadToDeg(
      std::acos(PrincipalAxis(back_from_front).dot(Eigen::Vector3d::UnitZ())));
  EXPECT_NEAR(angle_deg, 179, 0.1);
}

TEST(FrontBackRig, TruePosesAreDiagnosedAsParallel) {
  const SyntheticRig rig = FrontBackRig();
  RigCalibration calibration;
  calibration.images.resize(rig.dataset.images.size());
  for (size_t k = 0; k < rig.dataset.images.size(); ++k) {
    const RigImage& image = rig.dataset.images[k];
    calibration.images[k].single_image_cam_from_world =
        rig.truth.cam_from_rig[image.camera_index] *
        rig.truth.rig_from_world[image.frameset_index];
  }
  std::string explanation;
  EXPECT_TRUE(PrincipalAxesAreParallel(
      rig.dataset, calibration, kMinDeterminingAxisAngleDeg, &explanation))
      << explanation;
  EXPECT_NE(explanation.find("anti-parallel"), std::string::npos)
      << explanation;
}

TEST(FrontBackRig, DefaultMethodFallsBackToRdRaAndCalibrates) {
  const SyntheticRig rig = FrontBackRig();
  RigCalibration calibration;
  PipelineReport report;
  ASSERT_TRUE(
      CalibrateRig(QuietDefaultOptions(), rig.dataset, &calibration, &report))
      << report.error;
  EXPECT_EQ(report.requested_method, CalibrationMethod::kRadial1D);
  EXPECT_EQ(report.used_method, CalibrationMethod::kRdRa);
  const auto diagnostic = std::find_if(
      report.diagnostics.begin(), report.diagnostics.end(),
      [](const Diagnostic& d) { return d.code == "parallel_principal_axes"; });
  ASSERT_NE(diagnostic, report.diagnostics.end());
  EXPECT_EQ(diagnostic->level, Diagnostic::Level::kWarning);
  EXPECT_FALSE(report.HasErrors());

  // The bounds of the pipeline test's stereo pair through the same fallback.
  const CalibrationError error = CompareCalibrations(
      rig.truth.cameras, rig.truth.cam_from_rig, calibration.cameras,
      calibration.cam_from_rig, /*align_scale=*/false);
  ASSERT_TRUE(error.ok()) << error.error;
  EXPECT_TRUE(calibration.camera_calibrated[0]);
  EXPECT_TRUE(calibration.camera_calibrated[1]);
  // The figures the README quotes.
  std::cout << "front/back rig via rd_ra: rotation " << error.MaxRotationDeg()
            << " deg, center " << 1000 * error.MaxCenterError() << " mm, focal "
            << error.MaxFocalErrorPercent() << " %, principal point "
            << error.MaxPrincipalPointErrorPx() << " px" << std::endl;
  EXPECT_LT(error.MaxRotationDeg(), 0.1);
  EXPECT_LT(error.MaxCenterError(), 0.005);
  EXPECT_LT(error.MaxFocalErrorPercent(), 0.5);
  EXPECT_LT(error.MaxPrincipalPointErrorPx(), 2.0);
  EXPECT_LT(report.final_rms_px, 1.0);
}

TEST(FrontBackRig, WithoutFallbackFailsWithTheReason) {
  const SyntheticRig rig = FrontBackRig();
  PipelineOptions options = QuietDefaultOptions();
  options.fallback_on_parallel_axes = false;
  RigCalibration calibration;
  PipelineReport report;
  EXPECT_FALSE(CalibrateRig(options, rig.dataset, &calibration, &report));
  EXPECT_NE(report.error.find("anti-parallel"), std::string::npos)
      << report.error;
  EXPECT_NE(report.error.find("rd_ra"), std::string::npos) << report.error;
}

}  // namespace front_back_rig_test
}  // namespace rig_calibrator
