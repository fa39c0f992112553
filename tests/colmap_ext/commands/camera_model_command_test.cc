// The calibrate command on a synthetic fisheye rig (fisheye_helmet5, 145-155
// degrees diagonal): a forced model that folds back inside the image, or
// that does not fold but cannot follow the lens (OPENCV), is an error for
// those cameras (non-zero exit, every output still written, the validity in
// the summary); with --RigCalibrator.camera_model auto the same
// data give a fisheye model per camera, as accurate as OPENCV_FISHEYE given
// by hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <boost/filesystem.hpp>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "colmap_ext/commands/commands.h"
#include "colmap_ext/lab_commands/lab_commands.h"
#include "tests/colmap_ext/colmap_testing.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace camera_model_command_test {

namespace fs = boost::filesystem;

using testing::RunCommand;

class CameraModelCommandTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    temp_ = new testing::ScopedTempDir();
    data_ = temp_->File("data");
    ASSERT_EQ(RunCommand(&RunSynthetic,
                         {"--preset", "fisheye_helmet5", "--output_path", data_,
                          "--num_framesets", "12", "--seed", "3"}),
              EXIT_SUCCESS);
  }
  static void TearDownTestSuite() { delete temp_; }

  // Exit code of a calibration with `model` into `output`.
  static int Calibrate(const std::string& model, const std::string& output) {
    return RunCommand(&RunCalibrate,
                      {"--correspondences_path", data_ + "/correspondences.txt",
                       "--output_path", output, "--RigCalibrator.camera_model",
                       model, "--RigCalibrator.refine_points", "0"});
  }

  static nlohmann::json ReadJson(const std::string& path) {
    std::ifstream file(path);
    EXPECT_TRUE(file.good()) << path;
    if (!file) return nlohmann::json::object();
    return nlohmann::json::parse(file);
  }

  // Per camera, the errors of `evaluate` against the ground truth.
  static nlohmann::json Errors(const std::string& calibration) {
    const std::string errors = calibration + "_errors.json";
    EXPECT_EQ(RunCommand(
                  &RunEvaluate,
                  {"--reference_path", data_ + "/ground_truth/camchain.yaml",
                   "--calibration_path", calibration, "--output_path", errors}),
              EXIT_SUCCESS);
    return ReadJson(errors)["cameras"];
  }

  static testing::ScopedTempDir* temp_;
  static std::string data_;
};

testing::ScopedTempDir* CameraModelCommandTest::temp_ = nullptr;
std::string CameraModelCommandTest::data_;

TEST_F(CameraModelCommandTest, FoldingModelIsAnErrorAndEverythingIsWritten) {
  // A one-term polynomial on a 150-degree lens: k1 < 0 makes it fold back
  // inside the image.
  const std::string output = temp_->File("simple_radial");
  EXPECT_NE(Calibrate("SIMPLE_RADIAL", output), EXIT_SUCCESS);
  for (const std::string file : {"cameras.bin", "images.bin", "rig_config.json",
                                 "camchain.yaml", "calibration_summary.json"}) {
    EXPECT_TRUE(fs::exists(output + "/" + file)) << file;
  }
  const nlohmann::json summary = ReadJson(output + "/calibration_summary.json");
  int num_invalid = 0;
  for (const nlohmann::json& camera : summary["cameras"]) {
    ASSERT_TRUE(camera.contains("validity")) << camera["name"];
    const nlohmann::json& validity = camera["validity"];
    std::cout << camera["name"] << " " << validity.dump() << std::endl;
    EXPECT_TRUE(camera["calibrated"].get<bool>());
    EXPECT_FALSE(camera.contains("model_choice"));
    if (validity["valid"].get<bool>()) continue;
    ++num_invalid;
    EXPECT_FALSE(validity["monotonic"].get<bool>());
    EXPECT_LT(validity["fold_radius_px"].get<double>(),
              validity["corner_radius_px"].get<double>());
    EXPECT_EQ(validity["suggested_model"], "OPENCV_FISHEYE");
  }
  EXPECT_EQ(num_invalid, 5);
  int num_errors = 0;
  for (const nlohmann::json& diagnostic : summary["diagnostics"]) {
    if (diagnostic.get<std::string>().rfind(
            "error invalid_camera_model: camera cam", 0) == 0) {
      ++num_errors;
    }
  }
  EXPECT_EQ(num_errors, 5);
}

TEST_F(CameraModelCommandTest, OpenCVOnAFisheyeIsAnErrorThoughItDoesNotFold) {
  // The fitted OPENCV comes out with k2 > 0: one-to-one over the image and
  // an RMS near 1 px, but its radial residuals are systematic ring by ring
  // and its projections beyond the data 15-75 px off. Every camera is an
  // error with OPENCV_FISHEYE suggested; everything is still written.
  const std::string output = temp_->File("opencv");
  EXPECT_NE(Calibrate("OPENCV", output), EXIT_SUCCESS);
  for (const std::string file : {"cameras.bin", "rig_config.json",
                                 "camchain.yaml", "calibration_summary.json"}) {
    EXPECT_TRUE(fs::exists(output + "/" + file)) << file;
  }
  const nlohmann::json summary = ReadJson(output + "/calibration_summary.json");
  ASSERT_EQ(summary["cameras"].size(), 5u);
  for (const nlohmann::json& camera : summary["cameras"]) {
    ASSERT_TRUE(camera.contains("validity")) << camera["name"];
    const nlohmann::json& validity = camera["validity"];
    std::cout << camera["name"] << " " << validity.dump() << std::endl;
    EXPECT_TRUE(camera["calibrated"].get<bool>());
    EXPECT_TRUE(validity["monotonic"].get<bool>()) << camera["name"];
    EXPECT_FALSE(validity["fits_data"].get<bool>()) << camera["name"];
    EXPECT_FALSE(validity["valid"].get<bool>()) << camera["name"];
    EXPECT_EQ(validity["suggested_model"], "OPENCV_FISHEYE");
    double worst_bias = 0;
    for (const nlohmann::json& ring : validity["radial_residual_rings"]) {
      worst_bias =
          std::max(worst_bias, std::abs(ring["mean_radial_px"].get<double>()));
    }
    EXPECT_GT(worst_bias, 0.25) << camera["name"];
  }
  int num_errors = 0;
  for (const nlohmann::json& diagnostic : summary["diagnostics"]) {
    const std::string text = diagnostic;
    if (text.rfind("error invalid_camera_model: camera cam", 0) == 0 &&
        text.find("does not follow the lens") != std::string::npos) {
      ++num_errors;
    }
  }
  EXPECT_EQ(num_errors, 5);
}

TEST_F(CameraModelCommandTest, AutoChoosesFisheyeAsAccurateAsByHand) {
  const std::string by_hand = temp_->File("opencv_fisheye");
  const std::string automatic = temp_->File("auto");
  ASSERT_EQ(Calibrate("OPENCV_FISHEYE", by_hand), EXIT_SUCCESS);
  // A named summary: a range-for over a member of the temporary would read
  // it after its end (ASan's heap-use-after-free).
  const nlohmann::json hand_summary =
      ReadJson(by_hand + "/calibration_summary.json");
  for (const nlohmann::json& camera : hand_summary["cameras"]) {
    EXPECT_TRUE(camera["validity"]["fits_data"].get<bool>()) << camera["name"];
  }
  ASSERT_EQ(Calibrate("auto", automatic), EXIT_SUCCESS);
  const nlohmann::json summary =
      ReadJson(automatic + "/calibration_summary.json");
  for (const nlohmann::json& camera : summary["cameras"]) {
    const std::string model = camera["model"];
    EXPECT_NE(model.find("FISHEYE"), std::string::npos) << camera["name"];
    ASSERT_TRUE(camera.contains("model_choice"));
    EXPECT_EQ(camera["model_choice"]["chosen"], model);
    EXPECT_TRUE(camera["validity"]["valid"].get<bool>());
    EXPECT_TRUE(camera["validity"]["fits_data"].get<bool>());
    int num_chosen = 0;
    for (const nlohmann::json& candidate :
         camera["model_choice"]["candidates"]) {
      num_chosen += candidate["chosen"].get<bool>();
    }
    EXPECT_EQ(num_chosen, 1);
  }
  const nlohmann::json hand_errors = Errors(by_hand);
  const nlohmann::json auto_errors = Errors(automatic);
  ASSERT_EQ(hand_errors.size(), 5u);
  ASSERT_EQ(auto_errors.size(), 5u);
  for (size_t c = 0; c < 5; ++c) {
    const nlohmann::json& hand = hand_errors[c];
    const nlohmann::json& chosen = auto_errors[c];
    std::cout << hand["name"] << " rotation " << chosen["rotation_deg"]
              << " (by hand " << hand["rotation_deg"] << ") deg, center "
              << chosen["center_error"] << " (" << hand["center_error"]
              << "), mean projection " << chosen["mean_projection_diff_px"]
              << " (" << hand["mean_projection_diff_px"] << ") px" << std::endl;
    // As accurate as the true model given by hand: within 1.5 times its
    // error or a small absolute slack.
    for (const auto& [key, slack] : std::vector<std::pair<std::string, double>>{
             {"rotation_deg", 0.005},
             {"center_error", 0.0005},
             {"mean_projection_diff_px", 0.05}}) {
      EXPECT_LE(chosen[key].get<double>(),
                1.5 * hand[key].get<double>() + slack)
          << hand["name"] << " " << key;
    }
  }
}

}  // namespace camera_model_command_test
}  // namespace rig_calibrator
