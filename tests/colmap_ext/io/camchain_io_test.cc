#include "colmap_ext/io/camchain_io.h"

#include <colmap/base/camera_models.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <random>

#include "tests/testing.h"

namespace rig_calibrator {
namespace camchain_io_test {

colmap::Camera MakeCamera(const std::string& model,
                          const std::vector<double>& params, int width = 640,
                          int height = 480) {
  colmap::Camera camera;
  camera.SetModelIdFromName(model);
  camera.SetWidth(width);
  camera.SetHeight(height);
  camera.SetParams(params);
  EXPECT_TRUE(camera.VerifyParams()) << model;
  return camera;
}

// Largest pixel distance between the projections of the two cameras of
// points spread over a cone in front of them (the first camera's image).
double MaxProjectionDifference(const colmap::Camera& a,
                               const colmap::Camera& b) {
  double max_difference = 0;
  for (int iy = 0; iy <= 10; ++iy) {
    for (int ix = 0; ix <= 10; ++ix) {
      const Eigen::Vector2d pixel(0.5 + (a.Width() - 1.0) * ix / 10,
                                  0.5 + (a.Height() - 1.0) * iy / 10);
      const Eigen::Vector2d world = a.ImageToWorld(pixel);
      max_difference =
          std::max(max_difference,
                   (a.WorldToImage(world) - b.WorldToImage(world)).norm());
    }
  }
  return max_difference;
}

Rigid3d RandomPose(std::mt19937* random) {
  std::normal_distribution<double> normal;
  return Rigid3d(
      Eigen::Quaterniond(normal(*random), normal(*random), normal(*random),
                         normal(*random)),
      Eigen::Vector3d(normal(*random), normal(*random), normal(*random)));
}

TEST(CamchainIo, EveryColmapModelConverts) {
  struct Case {
    std::string model;
    std::vector<double> params;
    std::string distortion_model;
    bool exact;
  };
  const std::vector<Case> cases = {
      {"SIMPLE_PINHOLE", {500, 320, 240}, "radtan", true},
      {"PINHOLE", {500, 510, 320, 240}, "radtan", true},
      {"SIMPLE_RADIAL", {500, 320, 240, -0.1}, "radtan", true},
      {"RADIAL", {500, 320, 240, -0.1, 0.02}, "radtan", true},
      {"OPENCV", {500, 510, 320, 240, -0.1, 0.02, 1e-3, -2e-3}, "radtan", true},
      {"FULL_OPENCV",
       {500, 510, 320, 240, -0.1, 0.02, 1e-3, -2e-3, 0, 0, 0, 0},
       "radtan",
       true},
      {"FULL_OPENCV",
       {500, 510, 320, 240, -0.1, 0.02, 1e-3, -2e-3, 0.003, 0.001, 0, 0},
       "radtan",
       false},
      {"OPENCV_FISHEYE",
       {300, 310, 320, 240, 0.05, -0.01, 0.002, -1e-4},
       "equidistant",
       true},
      {"SIMPLE_RADIAL_FISHEYE", {300, 320, 240, 0.05}, "equidistant", true},
      {"RADIAL_FISHEYE", {300, 320, 240, 0.05, -0.01}, "equidistant", true},
      {"FOV", {400, 410, 320, 240, 0.9}, "fov", true},
      {"THIN_PRISM_FISHEYE",
       {300, 310, 320, 240, 0.05, -0.01, 0, 0, 0.002, -1e-4, 0, 0},
       "equidistant",
       true},
      {"THIN_PRISM_FISHEYE",
       {300, 310, 320, 240, 0.05, -0.01, 1e-4, -2e-4, 0.002, -1e-4, 1e-4, 0},
       "equidistant",
       false},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.model);
    const colmap::Camera camera = MakeCamera(c.model, c.params);
    KalibrCamera kalibr;
    std::string error;
    ASSERT_TRUE(ColmapToKalibrCamera(camera, &kalibr, &error)) << error;
    EXPECT_EQ(kalibr.camera_model, "pinhole");
    EXPECT_EQ(kalibr.distortion_model, c.distortion_model);
    EXPECT_EQ(kalibr.exact, c.exact);
    EXPECT_EQ(kalibr.width, 640);
    EXPECT_EQ(kalibr.height, 480);
    // Kalibr's principal point is COLMAP's minus half a pixel.
    EXPECT_EQ(kalibr.intrinsics[2], camera.PrincipalPointX() - 0.5);
    EXPECT_EQ(kalibr.intrinsics[3], camera.PrincipalPointY() - 0.5);
    colmap::Camera back;
    ASSERT_TRUE(KalibrToColmapCamera(kalibr, &back, &error)) << error;
    const double difference = MaxProjectionDifference(camera, back);
    if (c.exact) {
      EXPECT_LT(difference, 1e-9);
    } else {
      // The fit is close, and its reported error bounds the difference.
      EXPECT_GT(kalibr.max_fit_error_px, 0);
      EXPECT_LT(kalibr.max_fit_error_px, 1.0);
      EXPECT_LT(difference, kalibr.max_fit_error_px + 1e-6);
    }
  }
}

TEST(CamchainIo, RoundTripThroughFile) {
  std::mt19937 random(3);
  RigDescription rig;
  rig.cameras.resize(4);
  const std::vector<colmap::Camera> cameras = {
      MakeCamera("OPENCV_FISHEYE",
                 {300, 310, 320.25, 240.75, 0.05, -0.01, 0.002, -1e-4}),
      MakeCamera("OPENCV", {500, 510, 330, 250, -0.1, 0.02, 1e-3, -2e-3}, 752,
                 480),
      MakeCamera("FOV", {400, 410, 320, 240, 0.9}),
      MakeCamera("PINHOLE", {500, 500, 320, 240})};
  for (int c = 0; c < 4; ++c) {
    rig.cameras[c].name = "cam" + std::to_string(c);
    rig.cameras[c].image_prefix = rig.cameras[c].name + "/";
    rig.cameras[c].camera = cameras[c];
    rig.cameras[c].cam_from_rig = c == 0 ? Rigid3d() : RandomPose(&random);
  }
  // cam2 is not calibrated: left out, and the chain goes cam1 -> cam3.
  rig.cameras[2].camera.reset();
  rig.cameras[2].cam_from_rig.reset();

  testing::ScopedTempDir dir;
  const std::string path = dir.File("camchain.yaml");
  std::vector<std::string> notes;
  std::string error;
  ASSERT_TRUE(WriteCamchainYaml(path, rig, &notes, &error)) << error;
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("cam2 is not calibrated"), std::string::npos);

  // The file as Kalibr reads it: floats with a decimal point, T_cn_cnm1 =
  // cam_n_from_cam_(n-1), principal point shifted by half a pixel.
  const YAML::Node root = YAML::LoadFile(path);
  EXPECT_EQ(root["cam0"]["intrinsics"][2].as<std::string>(), "319.75");
  EXPECT_EQ(root["cam0"]["intrinsics"][3].as<std::string>(), "240.25");
  EXPECT_EQ(root["cam1"]["intrinsics"][0].as<std::string>(), "500.0");
  EXPECT_EQ(root["cam1"]["resolution"][0].as<std::string>(), "752");
  EXPECT_EQ(root["cam1"]["distortion_model"].as<std::string>(), "radtan");
  EXPECT_EQ(root["cam1"]["rostopic"].as<std::string>(), "/cam1/image_raw");
  EXPECT_FALSE(root["cam0"]["T_cn_cnm1"]);
  EXPECT_FALSE(root["cam3"]);
  Eigen::Matrix4d t;
  for (int r = 0; r < 4; ++r) {
    for (int k = 0; k < 4; ++k) {
      t(r, k) = root["cam2"]["T_cn_cnm1"][r][k].as<double>();
    }
  }
  const Rigid3d expected =
      *rig.cameras[3].cam_from_rig * rig.cameras[1].cam_from_rig->Inverse();
  EXPECT_LT((t.topRows<3>() - expected.ToMatrix()).norm(), 1e-12);

  RigDescription read;
  ASSERT_TRUE(ReadCamchainYaml(path, &read, &error)) << error;
  ASSERT_EQ(read.cameras.size(), 3u);
  const int written[3] = {0, 1, 3};
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    const RigDescriptionCamera& original = rig.cameras[written[i]];
    EXPECT_EQ(read.cameras[i].name, "cam" + std::to_string(i));
    ASSERT_TRUE(read.cameras[i].camera && read.cameras[i].cam_from_rig);
    EXPECT_EQ(read.cameras[i].camera->Width(), original.camera->Width());
    EXPECT_EQ(read.cameras[i].camera->Height(), original.camera->Height());
    // Kalibr's pinhole-radtan and pinhole-equidistant come back as OPENCV and
    // OPENCV_FISHEYE; PINHOLE is written as radtan with zero distortion.
    const char* const read_models[3] = {"OPENCV_FISHEYE", "OPENCV", "OPENCV"};
    EXPECT_EQ(read.cameras[i].camera->ModelName(), read_models[i]);
    EXPECT_LT(
        MaxProjectionDifference(*original.camera, *read.cameras[i].camera),
        1e-9);
    EXPECT_NEAR(read.cameras[i].camera->PrincipalPointX(),
                original.camera->PrincipalPointX(), 1e-12);
    // The rig frame is cam0's, which is the original reference.
    EXPECT_LT((read.cameras[i].cam_from_rig->ToMatrix() -
               original.cam_from_rig->ToMatrix())
                  .norm(),
              1e-12);
  }
}

// The capture timing (camera_timing.h) in Kalibr's fields, with the sign
// t_ref = t_cam + timeshift_cam_imu (the reference camera in the IMU's
// place): delta_c minus the offset removed from the camera's names; the
// line delay only when estimated; read back. Without a timing the file has
// none of these fields or their comments.
TEST(CamchainIo, CaptureTimingFieldsAreWrittenAndReadBack) {
  RigDescription rig;
  rig.cameras.resize(3);
  for (int c = 0; c < 3; ++c) {
    rig.cameras[c].name = "cam" + std::to_string(c);
    rig.cameras[c].camera = MakeCamera("PINHOLE", {500, 500, 320, 240});
    rig.cameras[c].cam_from_rig = Rigid3d();
  }
  testing::ScopedTempDir dir;
  std::string error;
  ASSERT_TRUE(WriteCamchainYaml(dir.File("untimed.yaml"), rig, nullptr, &error))
      << error;
  const std::string untimed = testing::ReadBytes(dir.File("untimed.yaml"));
  for (const char* field : {"timeshift", "line_delay", "timing_source"}) {
    EXPECT_EQ(untimed.find(field), std::string::npos) << field;
  }
  RigDescription read;
  ASSERT_TRUE(ReadCamchainYaml(dir.File("untimed.yaml"), &read, &error))
      << error;
  EXPECT_FALSE(read.cameras[1].timing);

  rig.cameras[0].timing.emplace();  // the reference: 0 by definition
  CameraTiming& measured = rig.cameras[1].timing.emplace();
  measured.time_offset_s = 0.0482;
  measured.time_offset_sigma_s = 0.0003;
  // Its names were 0.030 s late and that was removed before grouping: its
  // own timestamps need +0.0182 s.
  rig.cameras[1].timestamp_offset_s = 0.030;
  CameraTiming& estimated = rig.cameras[2].timing.emplace();
  estimated.time_offset_s = -0.0125;
  estimated.time_offset_sigma_s = 0.0001;
  estimated.line_delay_s_per_row = 2.9e-5;
  estimated.line_delay_sigma_s_per_row = 4e-7;
  estimated.source = TimingSource::kEstimatedInAdjustment;
  const std::string path = dir.File("camchain.yaml");
  ASSERT_TRUE(WriteCamchainYaml(path, rig, nullptr, &error)) << error;
  const std::string text = testing::ReadBytes(path);
  EXPECT_NE(text.find("t_ref = t_cam + timeshift_cam_imu"), std::string::npos)
      << text;
  EXPECT_NE(text.find("the reference camera cam0 takes its place"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("  # timeshift_cam_imu = the capture-time offset "
                      "against the frameset times (0.0482 s) - the offset "
                      "removed from the camera's names before grouping (0.03 "
                      "s)"),
            std::string::npos)
      << text;
  const YAML::Node root = YAML::LoadFile(path);
  EXPECT_EQ(root["cam0"]["timeshift_cam_imu"].as<double>(), 0);
  EXPECT_NEAR(root["cam1"]["timeshift_cam_imu"].as<double>(), 0.0182, 1e-15);
  EXPECT_EQ(root["cam1"]["timeshift_cam_imu_sigma"].as<double>(), 0.0003);
  EXPECT_FALSE(root["cam1"]["line_delay"]);
  EXPECT_EQ(root["cam1"]["timing_source"].as<std::string>(),
            "measured after calibration");
  EXPECT_EQ(root["cam2"]["line_delay"].as<double>(), 2.9e-5);
  EXPECT_EQ(root["cam2"]["line_delay_sigma"].as<double>(), 4e-7);
  EXPECT_EQ(root["cam2"]["timing_source"].as<std::string>(),
            "estimated in the adjustment");

  ASSERT_TRUE(ReadCamchainYaml(path, &read, &error)) << error;
  ASSERT_EQ(read.cameras.size(), 3u);
  ASSERT_TRUE(read.cameras[0].timing && read.cameras[1].timing &&
              read.cameras[2].timing);
  EXPECT_EQ(read.cameras[0].timing->time_offset_s, 0);
  EXPECT_NEAR(read.cameras[1].timing->time_offset_s, 0.0182, 1e-15);
  EXPECT_EQ(read.cameras[1].timestamp_offset_s, 0);
  EXPECT_EQ(read.cameras[1].timing->time_offset_sigma_s, 0.0003);
  EXPECT_FALSE(read.cameras[1].timing->line_delay_s_per_row);
  EXPECT_EQ(read.cameras[1].timing->source,
            TimingSource::kMeasuredAfterCalibration);
  EXPECT_EQ(*read.cameras[2].timing->line_delay_s_per_row, 2.9e-5);
  EXPECT_EQ(read.cameras[2].timing->line_delay_sigma_s_per_row, 4e-7);
  EXPECT_EQ(read.cameras[2].timing->source,
            TimingSource::kEstimatedInAdjustment);

  // Malformed timing fields are refused, naming the file, camera and field.
  const std::string bad = dir.File("bad.yaml");
  for (const auto& [field, message] :
       std::vector<std::pair<std::string, std::string>>{
           {"  timeshift_cam_imu: soon\n", "timeshift_cam_imu must be a finite"},
           {"  timeshift_cam_imu_sigma: 0.1\n", "without timeshift_cam_imu"},
           {"  line_delay: 1e-5\n  timing_source: guessed\n",
            "timing_source must be"}}) {
    std::ofstream(bad) << untimed << field;
    EXPECT_FALSE(ReadCamchainYaml(bad, &read, &error)) << field;
    EXPECT_NE(error.find(bad + ": cam2: "), std::string::npos) << error;
    EXPECT_NE(error.find(message), std::string::npos) << error;
  }
}

TEST(CamchainIo, ApproximationIsNotedInFile) {
  RigDescription rig;
  rig.cameras.resize(2);
  for (int c = 0; c < 2; ++c) {
    rig.cameras[c].name = "cam" + std::to_string(c);
    rig.cameras[c].camera = MakeCamera(
        "FULL_OPENCV",
        {500, 510, 320, 240, -0.1, 0.02, 1e-3, -2e-3, 0.003 * c, 0, 0, 0});
    rig.cameras[c].cam_from_rig = Rigid3d();
  }
  testing::ScopedTempDir dir;
  std::vector<std::string> notes;
  std::string error;
  ASSERT_TRUE(WriteCamchainYaml(dir.File("c.yaml"), rig, &notes, &error));
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("cam1 (cam1) approximates FULL_OPENCV by Kalibr "
                          "radtan"),
            std::string::npos)
      << notes[0];
  std::ifstream file(dir.File("c.yaml"));
  const std::string text((std::istreambuf_iterator<char>(file)),
                         std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("# cam0 is the rig camera cam0 (image prefix ), COLMAP "
                      "FULL_OPENCV, converted exactly."),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("approximated: radtan fitted by least squares"),
            std::string::npos);
}

TEST(CamchainIo, RefusesWhatItCannotRepresent) {
  testing::ScopedTempDir dir;
  const std::string path = dir.File("c.yaml");
  auto read_error = [&](const std::string& text) {
    std::ofstream(path) << text;
    RigDescription rig;
    std::string error;
    EXPECT_FALSE(ReadCamchainYaml(path, &rig, &error)) << text;
    return error;
  };
  const std::string cam0 =
      "cam0:\n  camera_model: pinhole\n  intrinsics: [500.0, 500.0, 320.0, "
      "240.0]\n  distortion_model: radtan\n  distortion_coeffs: [0.0, 0.0, "
      "0.0, 0.0]\n  resolution: [640, 480]\n";
  EXPECT_NE(read_error("cam0:\n  camera_model: omni\n  intrinsics: [1.0, "
                       "500.0, 500.0, 320.0, 240.0]\n  distortion_model: "
                       "radtan\n  distortion_coeffs: [0.0, 0.0, 0.0, 0.0]\n  "
                       "resolution: [640, 480]\n")
                .find("omni has no COLMAP 3.8 equivalent"),
            std::string::npos);
  EXPECT_NE(read_error(cam0 + "cam1:\n  camera_model: pinhole\n  intrinsics: "
                              "[500.0, 500.0, 320.0, 240.0]\n  "
                              "distortion_model: radtan\n  "
                              "distortion_coeffs: [0.0, 0.0, 0.0, 0.0]\n  "
                              "resolution: [640, 480]\n")
                .find("cam1 needs T_cn_cnm1"),
            std::string::npos);
  EXPECT_NE(read_error(cam0 + "cam1:\n  T_cn_cnm1:\n  - [2.0, 0.0, 0.0, 0.0]\n"
                              "  - [0.0, 1.0, 0.0, 0.0]\n  - [0.0, 0.0, 1.0, "
                              "0.0]\n  - [0.0, 0.0, 0.0, 1.0]\n  "
                              "camera_model: pinhole\n  intrinsics: [500.0, "
                              "500.0, 320.0, 240.0]\n  distortion_model: "
                              "equidistant\n  distortion_coeffs: [0.0, 0.0, "
                              "0.0, 0.0]\n  resolution: [640, 480]\n")
                .find("not a rigid transform"),
            std::string::npos);
  EXPECT_NE(read_error("cam0:\n  camera_model: pinhole\n  intrinsics: [500.0, "
                       "500.0, 320.0, 240.0]\n  distortion_model: radtan\n  "
                       "distortion_coeffs: [0.0]\n  resolution: [640, 480]\n")
                .find("unsupported Kalibr distortion model 'radtan' with 1"),
            std::string::npos);
  EXPECT_NE(read_error("cam1: {}\n").find("has no cam0"), std::string::npos);
  EXPECT_NE(read_error("cam0: [\n").find("cannot read"), std::string::npos);

  colmap::Camera no_size = MakeCamera("PINHOLE", {500, 500, 320, 240}, 0, 0);
  KalibrCamera kalibr;
  std::string error;
  EXPECT_FALSE(ColmapToKalibrCamera(no_size, &kalibr, &error));
}

}  // namespace camchain_io_test
}  // namespace rig_calibrator
