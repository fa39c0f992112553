#include "colmap_ext/io/uncertainty_json.h"

#include <colmap/base/camera_models.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <limits>

#include "colmap_ext/io/camchain_io.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace uncertainty_json_test {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

colmap::Camera OpenCvCamera() {
  colmap::Camera camera;
  camera.SetModelIdFromName("OPENCV");
  camera.SetWidth(640);
  camera.SetHeight(480);
  camera.SetParams({500, 501, 320, 240, -0.3, 0.08, 1e-4, -2e-4});
  return camera;
}

// Two cameras: the first determined with a 2 x 2 projection grid (one cell
// the model does not unproject), the second undetermined (NaN sigmas).
CalibrationUncertainty TwoCameras() {
  CalibrationUncertainty uncertainty;
  uncertainty.computed = true;
  uncertainty.residual_scale_px = 0.5;
  uncertainty.method = "test method";
  CameraUncertainty determined;
  determined.computed = true;
  determined.determined = true;
  determined.params_stddev = {0.1, 0.1, 0.2, 0.3, 1e-3, 2e-3, 0, 0};
  determined.rotation_stddev_deg = 0.01;
  determined.translation_stddev = Eigen::Vector3d(1e-3, 2e-3, 3e-3);
  determined.center_in_rig_stddev = Eigen::Vector3d(4e-3, 5e-3, 6e-3);
  determined.projection.cols = 2;
  determined.projection.rows = 2;
  determined.projection.stddev_px = {0.1, 0.2, kNaN, 0.4};
  determined.projection.median_px = 0.2;
  determined.projection.max_px = 0.4;
  determined.projection.max_at = Eigen::Vector2d(480, 360);
  CameraUncertainty undetermined;
  undetermined.computed = true;
  undetermined.params_stddev = {kNaN, kNaN, 0.2, 0.3, 1e-3, 2e-3, 0, 0};
  undetermined.rotation_stddev_deg = kNaN;
  undetermined.center_in_rig_stddev = Eigen::Vector3d(kNaN, kNaN, kNaN);
  uncertainty.cameras = {determined, undetermined, CameraUncertainty()};
  return uncertainty;
}

TEST(UncertaintyJson, FollowsTheContractWithNullsForUndetermined) {
  nlohmann::ordered_json root;
  root["cameras"] = nlohmann::ordered_json::array({{{"name", "cam0"}},
                                                   {{"name", "cam1"}},
                                                   {{"name", "cam2"}}});
  AddUncertaintyJson(TwoCameras(), &root);
  EXPECT_EQ(root["uncertainty_method"], "test method");
  const nlohmann::ordered_json& first = root["cameras"][0]["uncertainty"];
  EXPECT_EQ(first["residual_scale_px"], 0.5);
  ASSERT_EQ(first["params_stddev"].size(), 8u);
  EXPECT_EQ(first["params_stddev"][2], 0.2);
  EXPECT_EQ(first["params_stddev"][6], 0);
  EXPECT_EQ(first["rotation_stddev_deg"], 0.01);
  EXPECT_EQ(first["translation_stddev"][2], 3e-3);
  EXPECT_EQ(first["center_in_rig_stddev"][0], 4e-3);
  const nlohmann::ordered_json& projection = first["projection_stddev_px"];
  EXPECT_EQ(projection["median"], 0.2);
  EXPECT_EQ(projection["max"], 0.4);
  EXPECT_EQ(projection["max_at"][0], 480);
  EXPECT_EQ(projection["grid"]["cols"], 2);
  EXPECT_EQ(projection["grid"]["rows"], 2);
  ASSERT_EQ(projection["grid"]["values"].size(), 4u);
  EXPECT_TRUE(projection["grid"]["values"][2].is_null());
  const nlohmann::ordered_json& second = root["cameras"][1]["uncertainty"];
  EXPECT_FALSE(second["determined"].get<bool>());
  EXPECT_TRUE(second["params_stddev"][0].is_null());
  EXPECT_TRUE(second["rotation_stddev_deg"].is_null());
  EXPECT_TRUE(second["projection_stddev_px"].is_null());
  EXPECT_TRUE(root["cameras"][2]["uncertainty"].is_null());
  EXPECT_EQ(root.dump().find("nan"), std::string::npos);
}

TEST(UncertaintyJson, NotComputedSaysWhy) {
  nlohmann::ordered_json root;
  root["cameras"] = nlohmann::ordered_json::array({{{"name", "cam0"}}});
  CalibrationUncertainty uncertainty;
  uncertainty.message = "no redundancy";
  AddUncertaintyJson(uncertainty, &root);
  EXPECT_TRUE(root["cameras"][0]["uncertainty"].is_null());
  EXPECT_EQ(root["uncertainty_method"], "not computed: no redundancy");
}

// The comments keep camchain.yaml a valid Kalibr file that the reader
// reads back to the same cameras.
TEST(UncertaintyJson, CamchainCommentsKeepTheFileReadable) {
  RigDescription rig;
  for (int c = 0; c < 3; ++c) {
    RigDescriptionCamera camera;
    camera.name = "cam" + std::to_string(c);
    camera.image_prefix = camera.name + "/";
    camera.camera = OpenCvCamera();
    camera.cam_from_rig =
        Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.1 * c, 0, 0));
    rig.cameras.push_back(camera);
  }
  const CalibrationUncertainty uncertainty = TwoCameras();
  AddUncertaintyComments(uncertainty, &rig);
  ASSERT_EQ(rig.cameras[0].comments.size(), 3u);
  EXPECT_EQ(rig.cameras[1].comments.size(), 2u);  // no projection grid
  EXPECT_TRUE(rig.cameras[2].comments.empty());   // not computed
  const testing::ScopedTempDir folder;
  std::string error;
  ASSERT_TRUE(WriteCamchainYaml(folder.File("camchain.yaml"), rig, nullptr,
                                &error))
      << error;
  const std::string text = testing::ReadBytes(folder.File("camchain.yaml"));
  EXPECT_NE(text.find("# 1-sigma uncertainty"), std::string::npos);
  EXPECT_NE(text.find("undetermined"), std::string::npos);
  EXPECT_NO_THROW(YAML::Load(text));
  RigDescription read;
  ASSERT_TRUE(ReadCamchainYaml(folder.File("camchain.yaml"), &read, &error))
      << error;
  ASSERT_EQ(read.cameras.size(), 3u);
  for (size_t c = 0; c < 3; ++c) {
    ASSERT_TRUE(read.cameras[c].camera);
    for (size_t k = 0; k < 8; ++k) {
      EXPECT_NEAR(read.cameras[c].camera->Params()[k],
                  rig.cameras[c].camera->Params()[k], 1e-9);
    }
  }
}

TEST(UncertaintyJson, TerminalLinesNameEveryComputedCamera) {
  const std::vector<std::string> lines =
      UncertaintyLines({"cam0", "cam1", "cam2"},
                       {OpenCvCamera(), OpenCvCamera(), OpenCvCamera()},
                       TwoCameras());
  ASSERT_EQ(lines.size(), 3u);  // heading, cam0, cam1
  EXPECT_NE(lines[1].find("cam0"), std::string::npos);
  EXPECT_NE(lines[1].find("projection median 0.200 max 0.400"),
            std::string::npos);
  EXPECT_NE(lines[2].find("undetermined"), std::string::npos);
}

// A camera whose focal lengths and principal point come from the model
// choice's spread (src/calibration/model_choice_spread.h): its
// "model_choice_stddev" in the summary, a note in its terminal line and a
// comment in camchain.yaml; a camera without it has none of the three.
TEST(UncertaintyJson, ModelChoiceSpreadIsShownWhereItIsTheSigma) {
  CalibrationUncertainty uncertainty = TwoCameras();
  uncertainty.cameras[0].model_choice_stddev = {0.1, 0.1, 0.2, 0, 0, 0, 0, 0};
  nlohmann::ordered_json root;
  root["cameras"] = nlohmann::ordered_json::array(
      {{{"name", "cam0"}}, {{"name", "cam1"}}, {{"name", "cam2"}}});
  AddUncertaintyJson(uncertainty, &root);
  const nlohmann::ordered_json& first = root["cameras"][0]["uncertainty"];
  ASSERT_EQ(first["model_choice_stddev"].size(), 8u);
  EXPECT_EQ(first["model_choice_stddev"][2], 0.2);
  EXPECT_EQ(first["model_choice_stddev"][3], 0);
  EXPECT_FALSE(root["cameras"][1]["uncertainty"].contains("model_choice_stddev"));

  const std::vector<std::string> lines =
      UncertaintyLines({"cam0", "cam1", "cam2"},
                       {OpenCvCamera(), OpenCvCamera(), OpenCvCamera()},
                       uncertainty);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_NE(lines[1].find("f and pp at least the model choice's spread "
                          "(0.100/0.100, 0.200/0.000 px)"),
            std::string::npos)
      << lines[1];
  EXPECT_EQ(lines[2].find("model choice"), std::string::npos);

  RigDescription rig;
  for (int c = 0; c < 2; ++c) {
    RigDescriptionCamera camera;
    camera.name = "cam" + std::to_string(c);
    camera.camera = OpenCvCamera();
    rig.cameras.push_back(camera);
  }
  AddUncertaintyComments(uncertainty, &rig);
  ASSERT_EQ(rig.cameras[0].comments.size(), 4u);
  EXPECT_NE(rig.cameras[0].comments[1].find("model choice's spread"),
            std::string::npos);
  EXPECT_EQ(rig.cameras[1].comments.size(), 2u);
}

}  // namespace uncertainty_json_test
}  // namespace rig_calibrator
