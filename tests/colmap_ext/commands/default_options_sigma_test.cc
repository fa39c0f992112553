// Is the σ that the calibrate command reports honest on data with a map's
// errors? From scratch, with the command's default options (camera_model
// auto, refine_points, map_observations, refine_map, the uncertainty stage;
// MakePipelineOptions of a default CalibrateOptions), on synthetic ring5
// rigs (5 OPENCV cameras) whose map is made the way structure from motion
// makes one: 24 map images whose poses are off by 0.1 deg and 1 cm at
// random and drift by 0.3 deg and 0.1 % in scale along the sequence, their
// observations noisier than the rig's (0.7 px against 0.5 px), the map
// points triangulated from those observations through those poses, 30 %
// wrong matches, only points with a map track. Every true error is divided
// by its reported σ, per group: focal length, principal point, distortion
// (where auto chose the true model), rotation and centre in the rig (per
// axis); cameras with another model than the truth's apart, with their
// mean focal length and principal point (whose σ includes the model
// choice's spread, src/calibration/model_choice_spread.h). A standard
// normal has 0.683 within 1, 0.954 within 2, RMS 1.
//
// RIG_CALIBRATOR_SIGMA_RUNS (default 8) sets the number of runs: docs/accuracy.md
// gives the table of 40 (`RIG_CALIBRATOR_SIGMA_RUNS=40
// build/tests/default_options_sigma_test`). The test fails when σ is off
// by a factor 1.5 or more over the pooled groups, the bounds of a normal
// variable scaled by 1.5 or 1/1.5 (RMS, within 1, within 2), when any
// camera is left uncalibrated, when an error of a camera with the true
// model is beyond 6 σ, and when the warning framesets_disagree fires.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "colmap_ext/commands/calibrate_options.h"
#include "src/calibration/pipeline.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {
namespace default_options_sigma_test {

struct Group {
  std::vector<double> z;
  double Within(double k) const {
    return static_cast<double>(std::count_if(
               z.begin(), z.end(), [k](double v) { return std::abs(v) < k; })) /
           z.size();
  }
  double Rms() const {
    double sum = 0;
    for (const double v : z) sum += v * v;
    return std::sqrt(sum / z.size());
  }
};

SyntheticRigOptions MapLikeSfM(unsigned seed) {
  SyntheticRigOptions options;
  options.preset = RigPreset::kRing5;
  options.num_framesets = 12;
  options.points_per_image = 200;
  options.noise_px = 0.5;
  options.outlier_ratio = 0.3;
  options.num_map_images = 24;
  options.map_noise_px = 0.7;
  options.map_pose_noise_deg = 0.1;
  options.map_pose_noise = 0.01;
  options.map_drift_deg = 0.3;
  options.map_scale_drift = 0.001;
  options.triangulate_map_points = true;
  options.seed = seed;
  return options;
}

// The command's defaults, with a map given (refine_map on).
PipelineOptions CommandDefaults() {
  CalibrateOptions command;
  command.correspondences_path = "synthetic";
  command.input_path = "synthetic map";
  command.output_path = "unused";
  PipelineOptions pipeline;
  std::string error;
  EXPECT_TRUE(MakePipelineOptions(&command, &pipeline, &error)) << error;
  pipeline.print_progress = false;
  return pipeline;
}

TEST(DefaultOptionsSigma, ErrorsOverSigmaOnMapsLikeSfM) {
  const char* runs_env = std::getenv("RIG_CALIBRATOR_SIGMA_RUNS");
  const int num_runs = runs_env != nullptr ? std::max(1, std::atoi(runs_env)) : 8;
  const PipelineOptions pipeline = CommandDefaults();
  std::map<std::string, Group> groups;
  const std::vector<std::string> order = {
      "focal",
      "principal point",
      "distortion",
      "rotation",
      "centre",
      "focal, other model",
      "principal point, other model",
      "rotation, other model",
      "centre, other model"};
  std::map<std::string, int> chosen;
  for (int run = 0; run < num_runs; ++run) {
    SyntheticRig rig = GenerateSyntheticRig(MapLikeSfM(500 + run));
    KeepCorrespondencesWithMapTracks(&rig);
    // As the command loads a camera whose model is auto.
    for (RigCamera& camera : rig.dataset.cameras) {
      const int width = static_cast<int>(camera.camera.Width());
      const int height = static_cast<int>(camera.camera.Height());
      camera.choose_model = true;
      camera.camera.InitializeWithName("OPENCV", 1.2 * std::max(width, height),
                                       width, height);
    }
    RigCalibration calibration;
    PipelineReport report;
    ASSERT_TRUE(CalibrateRig(pipeline, rig.dataset, &calibration, &report))
        << "run " << run << ": " << report.error;
    ASSERT_TRUE(report.uncertainty.computed) << report.uncertainty.message;
    // The map's errors here are ones the covariance sees: the framesets do
    // not disagree beyond the noise, and the warning stays quiet.
    for (const Diagnostic& diagnostic : report.diagnostics) {
      EXPECT_NE(diagnostic.code, "framesets_disagree")
          << "run " << run << ": " << diagnostic.message;
    }
    for (size_t c = 0; c < rig.truth.cameras.size(); ++c) {
      ASSERT_TRUE(calibration.camera_calibrated[c])
          << "run " << run << " camera " << c;
      const CameraUncertainty& sigma = report.uncertainty.cameras[c];
      ASSERT_TRUE(sigma.computed && sigma.determined);
      const colmap::Camera& estimated = calibration.cameras[c];
      const colmap::Camera& truth = rig.truth.cameras[c];
      ++chosen[estimated.ModelName()];
      // Parameters compare only where auto chose the true model; with
      // another model the focal length (the mean of fx, fy) and the
      // principal point, whose sigma includes the model choice's spread.
      if (estimated.ModelId() != truth.ModelId()) {
        const std::vector<size_t>& focal = estimated.FocalLengthIdxs();
        double focal_sigma = 0;
        for (const size_t k : focal) {
          focal_sigma += sigma.params_stddev[k] / focal.size();
        }
        groups["focal, other model"].z.push_back(
            (estimated.MeanFocalLength() - truth.MeanFocalLength()) /
            focal_sigma);
        const std::vector<size_t>& pp = estimated.PrincipalPointIdxs();
        groups["principal point, other model"].z.push_back(
            (estimated.PrincipalPointX() - truth.PrincipalPointX()) /
            sigma.params_stddev[pp[0]]);
        groups["principal point, other model"].z.push_back(
            (estimated.PrincipalPointY() - truth.PrincipalPointY()) /
            sigma.params_stddev[pp[1]]);
      } else {
        for (size_t k = 0; k < truth.NumParams(); ++k) {
          const std::vector<size_t>& focal = truth.FocalLengthIdxs();
          const std::vector<size_t>& pp = truth.PrincipalPointIdxs();
          const std::string group =
              std::count(focal.begin(), focal.end(), k) ? "focal"
              : std::count(pp.begin(), pp.end(), k)     ? "principal point"
                                                        : "distortion";
          groups[group].z.push_back((estimated.Params()[k] -
                                     truth.Params()[k]) /
                                    sigma.params_stddev[k]);
        }
      }
      if (static_cast<int>(c) == rig.dataset.reference_camera) continue;
      const Rigid3d& pose = calibration.cam_from_rig[c];
      const Rigid3d& true_pose = rig.truth.cam_from_rig[c];
      const Eigen::AngleAxisd rotation_error(pose.RotationMatrix() *
                                             true_pose.RotationMatrix()
                                                 .transpose());
      const Eigen::Vector3d rotation_vector =
          rotation_error.angle() * rotation_error.axis();
      const Eigen::Vector3d center_error = pose.Center() - true_pose.Center();
      // A camera for which auto chose another model than the truth's is
      // counted apart: σ does not cover a model's bias.
      const std::string suffix =
          estimated.ModelId() == truth.ModelId() ? "" : ", other model";
      for (int k = 0; k < 3; ++k) {
        groups["rotation" + suffix].z.push_back(
            rotation_vector(k) /
            (sigma.rotation_axis_stddev_deg(k) * M_PI / 180));
        groups["centre" + suffix].z.push_back(center_error(k) /
                                              sigma.center_in_rig_stddev(k));
      }
    }
  }
  std::printf("%d runs, |error| / sigma per group (a standard normal: 0.683 "
              "0.954 1.000)\n",
              num_runs);
  std::printf("%-22s %6s %8s %8s %6s %7s\n", "group", "count", "within1",
              "within2", "RMS", "max");
  Group pooled;
  for (const std::string& name : order) {
    const Group& group = groups[name];
    if (group.z.empty()) continue;
    double max_z = 0;
    for (const double z : group.z) max_z = std::max(max_z, std::abs(z));
    std::printf("%-22s %6zu %8.3f %8.3f %6.3f %7.2f\n", name.c_str(),
                group.z.size(), group.Within(1), group.Within(2), group.Rms(),
                max_z);
    pooled.z.insert(pooled.z.end(), group.z.begin(), group.z.end());
    if (name.find("other model") == std::string::npos) {
      EXPECT_LT(max_z, 6) << name;
    }
  }
  std::printf("%-22s %6zu %8.3f %8.3f %6.3f\n", "all", pooled.z.size(),
              pooled.Within(1), pooled.Within(2), pooled.Rms());
  EXPECT_GT(pooled.Rms(), 1 / 1.5);
  EXPECT_LT(pooled.Rms(), 1.5);
  EXPECT_GT(pooled.Within(1), 0.495);
  EXPECT_LT(pooled.Within(1), 0.866);
  EXPECT_GT(pooled.Within(2), 0.817);
  std::printf("models chosen by auto (the truth: OPENCV):");
  for (const auto& [model, count] : chosen) {
    std::printf(" %s %d", model.c_str(), count);
  }
  std::printf("\n");
}

}  // namespace default_options_sigma_test
}  // namespace rig_calibrator
