// Degenerate rigs and data (issue 15), each run through the default pipeline
// (1dr): every principal axis parallel or anti-parallel (several stereo
// pairs facing one way, front/rear pairs) is diagnosed by name and calibrated
// by the rd_ra fallback; a rig that only rotates about a point and a nearly
// planar scene are calibrated (absolute poses against the map determine the
// rig without rig translation or depth), and a map in millimetres or in
// arbitrary units gives the same calibration up to the scale.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>

#include "src/calibration/pipeline.h"
#include "src/evaluation/evaluation.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {
namespace degenerate_rig_test {

// The pipeline tests' hard scenario: 0.5 px noise, 30% wrong matches, 10% of
// the images missing.
SyntheticRigOptions HardScenario(RigPreset preset) {
  SyntheticRigOptions options;
  options.preset = preset;
  options.num_framesets = 20;
  options.noise_px = 0.5;
  options.outlier_ratio = 0.3;
  options.missing_image_ratio = 0.1;
  options.seed = 5;
  return options;
}

struct Result {
  bool ok = false;
  PipelineReport report;
  RigCalibration calibration;
};

Result Calibrate(const SyntheticRig& rig) {
  PipelineOptions options;
  options.print_progress = false;
  options.num_threads = 1;
  Result result;
  result.ok =
      CalibrateRig(options, rig.dataset, &result.calibration, &result.report);
  return result;
}

const Diagnostic* FindDiagnostic(const PipelineReport& report,
                                 const std::string& code) {
  const auto it = std::find_if(
      report.diagnostics.begin(), report.diagnostics.end(),
      [&](const Diagnostic& diagnostic) { return diagnostic.code == code; });
  return it == report.diagnostics.end() ? nullptr : &*it;
}

// Every camera calibrated, within the bounds of the pipeline tests, and the
// errors printed (`what` names the case).
void ExpectAccurate(const SyntheticRig& rig, const Result& result,
                    const std::string& what) {
  ASSERT_TRUE(result.ok) << what << ": " << result.report.error;
  EXPECT_FALSE(result.report.HasErrors()) << what;
  const CalibrationError error = CompareCalibrations(
      rig.truth.cameras, rig.truth.cam_from_rig, result.calibration.cameras,
      result.calibration.cam_from_rig, /*align_scale=*/false);
  ASSERT_TRUE(error.ok()) << error.error;
  for (const bool calibrated : result.calibration.camera_calibrated) {
    EXPECT_TRUE(calibrated) << what;
  }
  std::cout << what << " (" << CalibrationMethodName(result.report.used_method)
            << "): rotation " << error.MaxRotationDeg() << " deg, center "
            << 1000 * error.MaxCenterError() << " mm, focal "
            << error.MaxFocalErrorPercent() << " %, principal point "
            << error.MaxPrincipalPointErrorPx() << " px, RMS "
            << result.report.final_rms_px << " px" << std::endl;
  EXPECT_LT(error.MaxRotationDeg(), 0.1) << what;
  EXPECT_LT(error.MaxCenterError(), 0.005) << what;
  EXPECT_LT(error.MaxFocalErrorPercent(), 0.5) << what;
  EXPECT_LT(error.MaxPrincipalPointErrorPx(), 2.0) << what;
  EXPECT_LT(result.report.final_rms_px, 1.0) << what;
}

// All principal axes parallel (two pairs facing forward) or parallel and
// anti-parallel (a forward pair and a backward pair): 1dr cannot fix the
// rig, the pipeline says so by name and what it does, and rd_ra calibrates.
TEST(DegenerateRig, ParallelAndAntiParallelPairsFallBackToRdRa) {
  for (const bool alternate : {false, true}) {
    SyntheticRigOptions options = HardScenario(RigPreset::kStereoPair);
    options.stereo_num_pairs = 2;
    options.stereo_alternate_facing = alternate;
    const SyntheticRig rig = GenerateSyntheticRig(options);
    ASSERT_EQ(rig.truth.cameras.size(), 4u);
    const Result result = Calibrate(rig);
    const std::string what =
        alternate ? "front and rear stereo pairs" : "two forward stereo pairs";
    EXPECT_EQ(result.report.used_method, CalibrationMethod::kRdRa) << what;
    const Diagnostic* diagnostic =
        FindDiagnostic(result.report, "parallel_principal_axes");
    ASSERT_NE(diagnostic, nullptr) << what;
    EXPECT_EQ(diagnostic->level, Diagnostic::Level::kWarning);
    EXPECT_NE(
        diagnostic->message.find(alternate ? "anti-parallel" : "parallel"),
        std::string::npos)
        << diagnostic->message;
    EXPECT_NE(diagnostic->message.find("falling back to rd_ra"),
              std::string::npos)
        << diagnostic->message;
    ExpectAccurate(rig, result, what);
  }
}

// No translation between framesets: each image's pose against the map still
// fixes cam_from_rig = cam_from_world * world_from_rig, so nothing is
// degenerate and 1dr calibrates.
TEST(DegenerateRig, RotationOnlyRigIsCalibrated) {
  SyntheticRigOptions options = HardScenario(RigPreset::kRing5);
  options.rotation_only = true;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  // The body origin stays put; the rig origin (camera 0, 0.15 m off the
  // ring's center) moves on a sphere about it (a normal walk moves 0.4 m
  // per frameset).
  const Eigen::Vector3d center0 =
      rig.truth.rig_from_world.front().Inverse().translation;
  for (const Rigid3d& rig_from_world : rig.truth.rig_from_world) {
    EXPECT_LT((rig_from_world.Inverse().translation - center0).norm(), 0.3);
  }
  const Result result = Calibrate(rig);
  EXPECT_EQ(result.report.used_method, CalibrationMethod::kRadial1D);
  ExpectAccurate(rig, result, "rotation-only rig");
}

// A (nearly) planar scene: every correct correspondence on the ground plane
// where the ground is seen (here all of them; the wrong matches are other
// map points).
TEST(DegenerateRig, NearlyPlanarSceneIsCalibrated) {
  SyntheticRigOptions options = HardScenario(RigPreset::kRing5);
  options.near_planar_ratio = 1.0;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  int num_correct = 0, num_on_ground = 0;
  for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
    const std::vector<Correspondence>& correspondences =
        rig.dataset.images[i].correspondences;
    for (size_t k = 0; k < correspondences.size(); ++k) {
      if (rig.is_outlier[i][k]) continue;
      ++num_correct;
      if (std::abs(correspondences[k].point3D.z()) < 1e-9) ++num_on_ground;
    }
  }
  const double planar_share = static_cast<double>(num_on_ground) / num_correct;
  std::cout << "planar scene: " << 100 * planar_share
            << " % of the correct correspondences on the ground plane"
            << std::endl;
  EXPECT_GT(planar_share, 0.99);
  const Result result = Calibrate(rig);
  for (const Diagnostic& diagnostic : result.report.diagnostics) {
    std::cout << "planar scene: " << diagnostic.code << ": "
              << diagnostic.message << std::endl;
  }
  ExpectAccurate(rig, result, "nearly planar scene");
}

// A map in millimetres (scale 1000) or in arbitrary units (0.0137): the same
// pixels and the map scaled give the same calibration up to the scale:
// intrinsics and rotations equal, translations scaled.
TEST(DegenerateRig, MapUnitsChangeOnlyTheScale) {
  SyntheticRigOptions options = HardScenario(RigPreset::kRing5);
  const SyntheticRig metric_rig = GenerateSyntheticRig(options);
  const Result metric = Calibrate(metric_rig);
  ASSERT_TRUE(metric.ok) << metric.report.error;
  for (const double scale : {1000.0, 0.0137}) {
    options.map_scale = scale;
    const SyntheticRig rig = GenerateSyntheticRig(options);
    const Result scaled = Calibrate(rig);
    ASSERT_TRUE(scaled.ok) << scaled.report.error;
    EXPECT_EQ(scaled.report.used_method, metric.report.used_method);
    EXPECT_EQ(scaled.report.num_used, metric.report.num_used) << scale;
    double max_param = 0, max_rotation_deg = 0, max_translation = 0;
    double max_initial_rotation_deg = 0;
    for (size_t c = 0; c < metric.calibration.cameras.size(); ++c) {
      const std::vector<double>& a = metric.calibration.cameras[c].Params();
      const std::vector<double>& b = scaled.calibration.cameras[c].Params();
      for (size_t k = 0; k < a.size(); ++k) {
        max_param = std::max(
            max_param, std::abs(a[k] - b[k]) / std::max(1.0, std::abs(a[k])));
      }
      const Rigid3d& p = metric.calibration.cam_from_rig[c];
      const Rigid3d& q = scaled.calibration.cam_from_rig[c];
      max_rotation_deg = std::max(
          max_rotation_deg, RotationDifferenceDeg(p.rotation, q.rotation));
      max_translation = std::max(
          max_translation, (p.translation - q.translation / scale).norm());
      max_initial_rotation_deg =
          std::max(max_initial_rotation_deg,
                   RotationDifferenceDeg(
                       metric.report.initial_cam_from_rig[c].rotation,
                       scaled.report.initial_cam_from_rig[c].rotation));
    }
    std::cout << "map scale " << scale << " vs metres: intrinsics (relative) "
              << max_param << ", cam_from_rig rotation " << max_rotation_deg
              << " deg, translation " << max_translation
              << " m; initial rig rotation " << max_initial_rotation_deg
              << " deg" << std::endl;
    // Not bit-identical: the solvers stop at relative tolerances (Ceres'
    // function_tolerance 1e-5, rig_adjustment_problem.cc) and the rig
    // initializer weighs translation in
    // radians per map unit (RigInitializerOptions::translation_weight), so
    // the iterations differ; the differences are four orders below the
    // calibration's own error (0.02 deg, 1 mm).
    EXPECT_LT(max_param, 1e-6) << scale;
    EXPECT_LT(max_rotation_deg, 1e-4) << scale;
    EXPECT_LT(max_translation, 1e-6) << scale;
    ExpectAccurate(
        [&] {
          SyntheticRig metric_truth = rig;
          for (Rigid3d& pose : metric_truth.truth.cam_from_rig) {
            pose.translation /= scale;
          }
          return metric_truth;
        }(),
        [&] {
          Result result = scaled;
          for (Rigid3d& pose : result.calibration.cam_from_rig) {
            pose.translation /= scale;
          }
          return result;
        }(),
        "map scale " + std::to_string(scale));
  }
}

}  // namespace degenerate_rig_test
}  // namespace rig_calibrator
