// The comparison of a calibration with a known rig (e.g. the sensor_from_rig
// of a COLMAP database's rig_sensors) and its place in
// calibration_summary.json.
#include "colmap_ext/io/calibration_summary.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/testing.h"

namespace rig_calibrator {
namespace calibration_summary_test {

Rigid3d Pose(const double angle, const Eigen::Vector3d& axis,
             const Eigen::Vector3d& translation) {
  return Rigid3d(
      Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis.normalized())),
      translation);
}

// Three cameras; the summary's rig frame is cam0's, the known rig's
// reference is cam1, so the comparison must re-express the result:
// cam_from_cam1 = cam_from_rig * (cam1_from_rig)^-1.
TEST(CompareWithKnownRig, ComparesInTheKnownRigsReferenceFrame) {
  const Rigid3d cam1_from_rig =
      Pose(0.4, Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0.2, 0, 0));
  const Rigid3d cam2_from_rig =
      Pose(-0.7, Eigen::Vector3d(0, 1, 0.1), Eigen::Vector3d(-0.1, 0.05, 0.3));
  CalibrationSummary summary;
  summary.cameras.resize(3);
  const char* names[] = {"cam0", "cam1", "cam2"};
  for (int c = 0; c < 3; ++c) summary.cameras[c].name = names[c];
  summary.cameras[0].cam_from_rig = Rigid3d();
  summary.cameras[1].cam_from_rig = cam1_from_rig;
  summary.cameras[2].cam_from_rig = cam2_from_rig;

  // The known rig: cam2 off by 0.01 rad about z and 3 mm along x; cam0
  // exact; its reference cam1 is not compared.
  const Rigid3d exact_cam2_from_cam1 = cam2_from_rig * cam1_from_rig.Inverse();
  const Rigid3d error =
      Pose(0.01, Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0.003, 0, 0));
  KnownRigPrior prior;
  prior.source = "database test.db, rig 2 (rig_sensors)";
  prior.reference_camera = 1;
  prior.cam_from_ref = {cam1_from_rig.Inverse(), Rigid3d(),
                        error * exact_cam2_from_cam1};
  CompareWithKnownRig(prior, &summary);

  EXPECT_EQ(summary.known_rig_source, prior.source);
  EXPECT_EQ(summary.known_rig_reference_camera, "cam1");
  ASSERT_EQ(summary.known_rig_comparison.size(), 2u);
  EXPECT_EQ(summary.known_rig_comparison[0].camera, "cam0");
  EXPECT_NEAR(summary.known_rig_comparison[0].rotation_error_deg, 0, 1e-9);
  EXPECT_NEAR(summary.known_rig_comparison[0].translation_error, 0, 1e-12);
  EXPECT_NEAR(summary.known_rig_comparison[0].known_translation_norm, 0.2,
              1e-12);
  const KnownPoseComparison& cam2 = summary.known_rig_comparison[1];
  EXPECT_EQ(cam2.camera, "cam2");
  EXPECT_NEAR(cam2.rotation_error_deg, 0.01 * 180 / M_PI, 1e-9);
  // t_known = R_e t + t_e; t_calibrated = t.
  const Eigen::Vector3d t = exact_cam2_from_cam1.translation;
  const Eigen::Vector3d t_known = error.rotation * t + error.translation;
  EXPECT_NEAR(cam2.translation_error, (t - t_known).norm(), 1e-12);
  EXPECT_NEAR(cam2.known_translation_norm, t_known.norm(), 1e-12);

  testing::ScopedTempDir temp;
  const std::string path = temp.File("calibration_summary.json");
  std::string write_error;
  ASSERT_TRUE(WriteCalibrationSummaryJson(path, summary, &write_error))
      << write_error;
  std::ifstream file(path);
  const nlohmann::json known = nlohmann::json::parse(file)["known_rig"];
  EXPECT_EQ(known["source"], prior.source);
  EXPECT_EQ(known["reference_camera"], "cam1");
  ASSERT_EQ(known["cameras"].size(), 2u);
  EXPECT_EQ(known["cameras"][1]["name"], "cam2");
  EXPECT_NEAR(known["cameras"][1]["rotation_error_deg"].get<double>(),
              cam2.rotation_error_deg, 1e-12);
}

TEST(CompareWithKnownRig, NothingWithoutAPriorOrACalibratedReference) {
  CalibrationSummary summary;
  summary.cameras.resize(2);
  summary.cameras[0].cam_from_rig = Rigid3d();
  CompareWithKnownRig(KnownRigPrior(), &summary);
  EXPECT_TRUE(summary.known_rig_source.empty());

  KnownRigPrior prior;
  prior.source = "database test.db, rig 2 (rig_sensors)";
  prior.reference_camera = 1;  // not calibrated
  prior.cam_from_ref = {Rigid3d(), Rigid3d()};
  CompareWithKnownRig(prior, &summary);
  EXPECT_TRUE(summary.known_rig_source.empty());
  EXPECT_TRUE(summary.known_rig_comparison.empty());

  testing::ScopedTempDir temp;
  const std::string path = temp.File("calibration_summary.json");
  std::string error;
  ASSERT_TRUE(WriteCalibrationSummaryJson(path, summary, &error)) << error;
  std::ifstream file(path);
  EXPECT_TRUE(nlohmann::json::parse(file)["known_rig"].is_null());
}

// "capture_time_offsets" only when the offsets were computed: per camera
// offset, sigma (null when infinite), observable, significant; the same
// summary without them writes the same bytes as before the field existed
// (no key at all).
TEST(CaptureTimeOffsetsJson, WrittenOnlyWhenComputed) {
  CalibrationSummary summary;
  summary.reference_camera = "cam0";
  summary.cameras.resize(2);
  summary.cameras[0].name = "cam0";
  summary.cameras[1].name = "cam1";
  testing::ScopedTempDir temp;
  const std::string untimed = temp.File("untimed.json");
  std::string error;
  ASSERT_TRUE(WriteCalibrationSummaryJson(untimed, summary, &error)) << error;
  std::ifstream untimed_file(untimed);
  EXPECT_FALSE(nlohmann::json::parse(untimed_file).contains(
      "capture_time_offsets"));

  summary.capture_timing.computed = true;
  summary.capture_timing.num_image_poses = 37;
  summary.capture_timing.rig_angular_speed_rad_s = M_PI / 6;
  summary.capture_timing.offsets.resize(2);
  summary.capture_timing.offsets[0].offset_sigma_s = INFINITY;
  summary.capture_timing.offsets[1].offset_s = 0.0123;
  summary.capture_timing.offsets[1].offset_sigma_s = 0.0004;
  summary.capture_timing.offsets[1].observable = true;
  summary.capture_timing.offsets[1].num_framesets_used = 18;
  summary.capture_timing.significant = {false, true};
  const std::string timed = temp.File("timed.json");
  ASSERT_TRUE(WriteCalibrationSummaryJson(timed, summary, &error)) << error;
  std::ifstream timed_file(timed);
  const nlohmann::json node =
      nlohmann::json::parse(timed_file)["capture_time_offsets"];
  EXPECT_EQ(node["reference_camera"], "cam0");
  EXPECT_EQ(node["num_image_poses"], 37);
  EXPECT_NEAR(node["rig_angular_speed_deg_s"].get<double>(), 30, 1e-12);
  EXPECT_TRUE(node["error"].is_null());
  ASSERT_EQ(node["cameras"].size(), 2u);
  EXPECT_TRUE(node["cameras"][0]["offset_sigma_s"].is_null());
  EXPECT_EQ(node["cameras"][1]["name"], "cam1");
  EXPECT_EQ(node["cameras"][1]["offset_s"].get<double>(), 0.0123);
  EXPECT_EQ(node["cameras"][1]["offset_sigma_s"].get<double>(), 0.0004);
  EXPECT_EQ(node["cameras"][1]["observable"], true);
  EXPECT_EQ(node["cameras"][1]["significant"], true);
  EXPECT_EQ(node["cameras"][1]["num_framesets_used"], 18);
}

// Each camera's "timing" (camera_timing.h) and the top-level
// "timestamp_offsets" only when there are some (offsets not all 0): the offset and its sigma,
// the line delay only when estimated, the source in words; the cameras
// without keep their keys as before.
TEST(CameraTimingJson, WrittenOnlyWhenPresent) {
  CalibrationSummary summary;
  summary.reference_camera = "cam0";
  summary.cameras.resize(3);
  for (int c = 0; c < 3; ++c) {
    summary.cameras[c].name = "cam" + std::to_string(c);
  }
  testing::ScopedTempDir temp;
  std::string error;
  ASSERT_TRUE(
      WriteCalibrationSummaryJson(temp.File("plain.json"), summary, &error))
      << error;
  const std::string plain = testing::ReadBytes(temp.File("plain.json"));
  EXPECT_EQ(plain.find("timing"), std::string::npos);
  EXPECT_EQ(plain.find("timestamp_offsets"), std::string::npos);
  // Timestamp names whose offsets are all 0: the same bytes.
  summary.timestamp_offsets_s = {0, 0, 0};
  ASSERT_TRUE(
      WriteCalibrationSummaryJson(temp.File("zero.json"), summary, &error))
      << error;
  EXPECT_EQ(testing::ReadBytes(temp.File("zero.json")), plain);

  summary.cameras[0].timing.emplace();
  CameraTiming& measured = summary.cameras[1].timing.emplace();
  measured.time_offset_s = 0.0482;
  measured.time_offset_sigma_s = 0.0003;
  CameraTiming& estimated = summary.cameras[2].timing.emplace();
  estimated.time_offset_s = -0.0125;
  estimated.time_offset_sigma_s = 0.0001;
  estimated.line_delay_s_per_row = 2.9e-5;
  estimated.line_delay_sigma_s_per_row = 4e-7;
  estimated.source = TimingSource::kEstimatedInAdjustment;
  summary.timestamp_offsets_s = {0, 0.030, -0.012};
  ASSERT_TRUE(
      WriteCalibrationSummaryJson(temp.File("timed.json"), summary, &error))
      << error;
  std::ifstream file(temp.File("timed.json"));
  const nlohmann::json root = nlohmann::json::parse(file);
  const nlohmann::json& cam1 = root["cameras"][1]["timing"];
  EXPECT_EQ(cam1["time_offset_s"].get<double>(), 0.0482);
  EXPECT_EQ(cam1["time_offset_sigma_s"].get<double>(), 0.0003);
  EXPECT_FALSE(cam1.contains("line_delay_s_per_row"));
  EXPECT_EQ(cam1["source"], "measured after calibration");
  const nlohmann::json& cam2 = root["cameras"][2]["timing"];
  EXPECT_EQ(cam2["line_delay_s_per_row"].get<double>(), 2.9e-5);
  EXPECT_EQ(cam2["line_delay_sigma_s_per_row"].get<double>(), 4e-7);
  EXPECT_EQ(cam2["source"], "estimated in the adjustment");
  EXPECT_EQ(root["cameras"][0]["timing"]["time_offset_s"].get<double>(), 0);
  EXPECT_EQ(root["timestamp_offsets"]["reference_camera"], "cam0");
  EXPECT_EQ(root["timestamp_offsets"]["offsets_s"]["cam1"].get<double>(),
            0.030);
  EXPECT_EQ(root["timestamp_offsets"]["offsets_s"]["cam2"].get<double>(),
            -0.012);
}

}  // namespace calibration_summary_test
}  // namespace rig_calibrator
