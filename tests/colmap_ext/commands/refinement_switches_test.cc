// --RigCalibrator.refine_focal_length / refine_principal_point /
// refine_extra_params on the command: a held parameter is exactly (bit for
// bit) its given value in every output that carries it (the COLMAP model's
// cameras, camchain.yaml, rig_config.json, calibration_summary.json), and
// bad values or a held focal length without a given one are refused.
#include <colmap/base/reconstruction.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <boost/filesystem.hpp>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "colmap_ext/commands/commands.h"
#include "colmap_ext/io/rig_reference_io.h"
#include "colmap_ext/lab_commands/lab_commands.h"
#include "src/rig/intrinsics_refinement.h"
#include "tests/colmap_ext/colmap_testing.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace refinement_switches_test {

namespace fs = boost::filesystem;

using testing::RunCommand;

class RefinementSwitchesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    data_ = temp_.File("data");
    ASSERT_EQ(
        RunCommand(&RunSynthetic, {"--output_path", data_, "--num_framesets",
                                   "12", "--seed", "5"}),
        EXIT_SUCCESS);
    // The given intrinsics: the truth moved by 0.37 px (principal point),
    // 2 px (focal) and 1e-3 (distortion), so that an estimate cannot pass
    // for a held value.
    std::ifstream truth_file(data_ + "/ground_truth/rig_config.json");
    nlohmann::json config = nlohmann::json::parse(truth_file);
    for (nlohmann::json& camera : config[0]["cameras"]) {
      std::vector<double> params = camera["camera_params"];
      params[0] += 2;
      params[1] += 2;
      params[2] += 0.37;
      params[3] -= 0.37;
      for (size_t i = 4; i < params.size(); ++i) params[i] += 1e-3;
      camera["camera_params"] = params;
    }
    given_path_ = temp_.File("given_rig_config.json");
    std::ofstream(given_path_) << config.dump(2);
    std::string error;
    RigDescription given;
    ASSERT_TRUE(ReadRigReference(given_path_, &given, &error)) << error;
    for (const RigDescriptionCamera& camera : given.cameras) {
      ASSERT_TRUE(camera.camera);
      given_[camera.name] = camera.camera->Params();
    }
    ASSERT_EQ(given_.size(), 5u);
  }

  std::vector<std::string> Arguments(const std::string& output,
                                     const std::string& option,
                                     const std::string& value) {
    return {"--correspondences_path",
            data_ + "/correspondences.txt",
            "--output_path",
            output,
            "--RigCalibrator.camera_model",
            "OPENCV",
            "--RigCalibrator.intrinsics_path",
            given_path_,
            "--RigCalibrator." + option,
            value};
  }

  // Per camera name, the parameters in each output of `output`.
  std::map<std::string, std::vector<std::vector<double>>> OutputParams(
      const std::string& output) {
    std::map<std::string, std::vector<std::vector<double>>> params;
    colmap::Reconstruction model;
    model.ReadBinary(output);
    for (const auto& [image_id, image] : model.Images()) {
      const std::string name = image.Name().substr(0, image.Name().find('/'));
      if (params[name].empty()) {
        params[name].push_back(model.Camera(image.CameraId()).Params());
      }
    }
    for (const std::string file : {"camchain.yaml", "rig_config.json"}) {
      RigDescription rig;
      std::string error;
      EXPECT_TRUE(ReadRigReference(output + "/" + file, &rig, &error)) << error;
      for (const RigDescriptionCamera& camera : rig.cameras) {
        params[camera.name].push_back(camera.camera->Params());
      }
    }
    std::ifstream summary_file(output + "/calibration_summary.json");
    summary_ = nlohmann::json::parse(summary_file);
    for (const nlohmann::json& camera : summary_["cameras"]) {
      params[camera["name"]].push_back(camera["params"]);
    }
    return params;
  }

  testing::ScopedTempDir temp_;
  std::string data_;
  std::string given_path_;
  std::map<std::string, std::vector<double>> given_;
  nlohmann::json summary_;
};

TEST_F(RefinementSwitchesTest, HeldParametersAreExactInEveryOutput) {
  const std::vector<std::pair<std::string, std::vector<int>>> cases = {
      {"refine_principal_point", {2, 3}},
      {"refine_focal_length", {0, 1}},
      {"refine_extra_params", {4, 5, 6, 7}}};
  // The given values are off the truth, so some held ones misfit the data:
  // a warning (not the invalid-model error) with the ring's numbers.
  int num_misfit_warnings = 0;
  for (const auto& [option, held] : cases) {
    SCOPED_TRACE(option);
    const std::string output = temp_.File(option);
    ASSERT_EQ(RunCommand(&RunCalibrate, Arguments(output, option, "0")),
              EXIT_SUCCESS);
    const auto outputs = OutputParams(output);
    ASSERT_EQ(outputs.size(), 5u);
    for (const auto& [name, params] : outputs) {
      SCOPED_TRACE(name);
      ASSERT_EQ(params.size(), 4u);  // model, camchain, rig_config, summary
      const std::vector<double>& given = given_.at(name);
      for (size_t output_index = 0; output_index < 4; ++output_index) {
        ASSERT_EQ(params[output_index].size(), 8u);
        for (size_t i = 0; i < 8; ++i) {
          const bool is_held =
              std::count(held.begin(), held.end(), static_cast<int>(i)) > 0;
          if (is_held) {
            EXPECT_EQ(params[output_index][i], given[i])
                << "output " << output_index << " param " << i;
          } else {
            EXPECT_NE(params[output_index][i], given[i])
                << "output " << output_index << " param " << i;
          }
        }
      }
    }
    const std::string key = option.substr(std::string("refine_").size());
    for (const nlohmann::json& camera : summary_["cameras"]) {
      EXPECT_FALSE(camera["refined"][key].get<bool>());
      EXPECT_EQ(camera["refined"].size(), 3u);
      ASSERT_TRUE(camera.contains("coverage"));
      EXPECT_GT(camera["coverage"]["fraction_cells"].get<double>(), 0.5);
      EXPECT_TRUE(camera["validity"]["valid"].get<bool>());
    }
    for (const nlohmann::json& diagnostic : summary_["diagnostics"]) {
      const std::string text = diagnostic;
      EXPECT_NE(text.rfind("error", 0), 0u) << text;
      if (text.rfind("warning held_intrinsics_misfit: camera cam", 0) == 0) {
        std::cout << option << ": " << text << std::endl;
        ++num_misfit_warnings;
      }
    }
  }
  EXPECT_GT(num_misfit_warnings, 0);
}

// cam1:0 holds cam1's principal point only.
TEST_F(RefinementSwitchesTest, PerCameraSwitch) {
  const std::string output = temp_.File("per_camera");
  ASSERT_EQ(RunCommand(&RunCalibrate,
                       Arguments(output, "refine_principal_point", "cam1:0")),
            EXIT_SUCCESS);
  for (const auto& [name, params] : OutputParams(output)) {
    for (const std::vector<double>& output_params : params) {
      EXPECT_EQ(output_params[2] == given_.at(name)[2], name == "cam1") << name;
    }
  }
}

// A held focal length needs a given one; bad values and unknown cameras are
// refused; nothing is written.
TEST_F(RefinementSwitchesTest, BadSwitchesAreRefused) {
  const std::string output = temp_.File("bad");
  std::vector<std::string> no_given = {"--correspondences_path",
                                       data_ + "/correspondences.txt",
                                       "--output_path",
                                       output,
                                       "--RigCalibrator.refine_focal_length",
                                       "0"};
  EXPECT_EQ(RunCommand(&RunCalibrate, no_given), EXIT_FAILURE);
  EXPECT_EQ(RunCommand(&RunCalibrate,
                       Arguments(output, "refine_principal_point", "2")),
            EXIT_FAILURE);
  EXPECT_EQ(RunCommand(&RunCalibrate,
                       Arguments(output, "refine_extra_params", "cam9:0")),
            EXIT_FAILURE);
  EXPECT_FALSE(fs::exists(output));
  // Without a given principal point, held means at the image centre.
  std::vector<std::string> centre = {"--correspondences_path",
                                     data_ + "/correspondences.txt",
                                     "--output_path",
                                     output,
                                     "--RigCalibrator.refine_principal_point",
                                     "0"};
  ASSERT_EQ(RunCommand(&RunCalibrate, centre), EXIT_SUCCESS);
  std::ifstream summary_file(output + "/calibration_summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  for (const nlohmann::json& camera : summary["cameras"]) {
    EXPECT_EQ(camera["params"][2].get<double>(),
              camera["width"].get<double>() / 2);
    EXPECT_EQ(camera["params"][3].get<double>(),
              camera["height"].get<double>() / 2);
  }
}

}  // namespace refinement_switches_test
}  // namespace rig_calibrator
