// The sub-commands end to end, in process: synthetic -> calibrate (from the
// correspondence file) -> evaluate, and bad input giving a clear, non-zero
// exit.
#include "colmap_ext/commands/commands.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <boost/filesystem.hpp>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "colmap_ext/io/correspondence_io.h"
#include "colmap_ext/io/map_reader.h"
#include "colmap_ext/lab_commands/lab_commands.h"
#include "src/calibration/calibration_method.h"
#include "tests/colmap_ext/colmap_testing.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace commands_test {

namespace fs = boost::filesystem;

using testing::RunCommand;

class CommandsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    data_ = temp_.File("data");
    ASSERT_EQ(
        RunCommand(&RunSynthetic, {"--output_path", data_, "--num_framesets",
                                   "12", "--seed", "5"}),
        EXIT_SUCCESS);
  }

  std::vector<std::string> CalibrateArguments(const std::string& output) {
    return {"--correspondences_path",
            data_ + "/correspondences.txt",
            "--output_path",
            output,
            "--RigCalibrator.camera_model",
            "OPENCV",
            "--output_type",
            "TXT"};
  }

  // The per-camera errors of `evaluate` against the ground truth; an empty
  // array (and a test failure) if it fails.
  nlohmann::json EvaluatedCameras(const std::string& calibration) {
    const std::string errors = temp_.File("errors.json");
    EXPECT_EQ(RunCommand(
                  &RunEvaluate,
                  {"--reference_path", data_ + "/ground_truth/camchain.yaml",
                   "--calibration_path", calibration, "--output_path", errors}),
              EXIT_SUCCESS);
    std::ifstream errors_file(errors);
    if (!errors_file) return nlohmann::json::array();
    return nlohmann::json::parse(errors_file)["cameras"];
  }

  testing::ScopedTempDir temp_;
  std::string data_;
};

TEST_F(CommandsTest, SyntheticCalibrateEvaluate) {
  const std::string output = temp_.File("calibration");
  ASSERT_EQ(RunCommand(&RunCalibrate, CalibrateArguments(output)),
            EXIT_SUCCESS);
  for (const std::string file :
       {"cameras.txt", "images.txt", "points3D.txt", "rigs.txt", "frames.txt",
        "rig_config.json", "rig_bundle_adjuster_config.json", "camchain.yaml",
        "calibration_summary.json", "correspondences.txt"}) {
    EXPECT_TRUE(fs::exists(output + "/" + file)) << file;
  }
  std::ifstream summary_file(output + "/calibration_summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary["method"], "1dr");

  const nlohmann::json cameras = EvaluatedCameras(output);
  ASSERT_EQ(cameras.size(), 5u);
  for (const nlohmann::json& camera : cameras) {
    EXPECT_LT(camera["rotation_deg"].get<double>(), 0.1);
    EXPECT_LT(camera["center_error"].get<double>(), 0.005);
    EXPECT_LT(camera["focal_error_percent"].get<double>(), 0.3);
  }
}

// The bundle adjustments on Ceres' solver (bundle_solver.h): a calibration
// as accurate as the own solver's.
TEST_F(CommandsTest, CeresBundleSolverCalibratesToo) {
  const std::string output = temp_.File("calibration");
  std::vector<std::string> arguments = CalibrateArguments(output);
  arguments.insert(arguments.end(), {"--RigCalibrator.bundle_solver", "ceres"});
  ASSERT_EQ(RunCommand(&RunCalibrate, arguments), EXIT_SUCCESS);
  const nlohmann::json cameras = EvaluatedCameras(output);
  ASSERT_EQ(cameras.size(), 5u);
  for (const nlohmann::json& camera : cameras) {
    EXPECT_LT(camera["rotation_deg"].get<double>(), 0.1);
    EXPECT_LT(camera["center_error"].get<double>(), 0.005);
    EXPECT_LT(camera["focal_error_percent"].get<double>(), 0.3);
  }
}

TEST_F(CommandsTest, RerunFromWrittenCorrespondencesReproducesTheResult) {
  const std::string first = temp_.File("first");
  ASSERT_EQ(RunCommand(&RunCalibrate, CalibrateArguments(first)), EXIT_SUCCESS);
  const std::string second = temp_.File("second");
  std::vector<std::string> arguments = CalibrateArguments(second);
  arguments[1] = first + "/correspondences.txt";
  ASSERT_EQ(RunCommand(&RunCalibrate, arguments), EXIT_SUCCESS);
  // The file rounds the pixels to what the format keeps, and Ceres's
  // multi-threaded evaluation rounds differently from run to run: the
  // intrinsics agree to far below any meaningful digit.
  std::ifstream a(first + "/cameras.txt"), b(second + "/cameras.txt");
  std::vector<std::string> tokens_a, tokens_b;
  for (std::string token; a >> token;) tokens_a.push_back(token);
  for (std::string token; b >> token;) tokens_b.push_back(token);
  ASSERT_EQ(tokens_a.size(), tokens_b.size());
  int num_numbers = 0;
  for (size_t k = 0; k < tokens_a.size(); ++k) {
    char* end = nullptr;
    const double value_a = std::strtod(tokens_a[k].c_str(), &end);
    if (*end != '\0' || end == tokens_a[k].c_str()) {
      EXPECT_EQ(tokens_a[k], tokens_b[k]);
      continue;
    }
    const double value_b = std::stod(tokens_b[k]);
    EXPECT_NEAR(value_a, value_b, 1e-6 * std::max(1.0, std::abs(value_a)));
    ++num_numbers;
  }
  EXPECT_GE(num_numbers, 5 * 11);  // id, size and 8 OPENCV parameters each
}

TEST_F(CommandsTest, BadInputFailsWithoutOutput) {
  const std::string output = temp_.File("out");
  std::vector<std::string> arguments = CalibrateArguments(output);
  // No input at all.
  EXPECT_EQ(RunCommand(&RunCalibrate, {"--output_path", output}), EXIT_FAILURE);
  // Unknown method, unknown camera model, unknown option.
  std::vector<std::string> bad_method = arguments;
  bad_method.insert(bad_method.end(), {"--RigCalibrator.method", "magic"});
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(RunCommand(&RunCalibrate, bad_method), EXIT_FAILURE);
  const std::string method_messages = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(method_messages.find("--RigCalibrator.method must be one of 1dr, "
                                 "rd_ra, rd, known, known_refine, known_ra, "
                                 "not magic"),
            std::string::npos)
      << method_messages;
  std::vector<std::string> bad_solver = arguments;
  bad_solver.insert(bad_solver.end(), {"--RigCalibrator.bundle_solver", "g2o"});
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(RunCommand(&RunCalibrate, bad_solver), EXIT_FAILURE);
  const std::string solver_messages = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(solver_messages.find(
                "--RigCalibrator.bundle_solver must be own or ceres, not g2o"),
            std::string::npos)
      << solver_messages;
  std::vector<std::string> bad_model = arguments;
  bad_model[5] = "NOT_A_MODEL";
  EXPECT_EQ(RunCommand(&RunCalibrate, bad_model), EXIT_FAILURE);
  std::vector<std::string> bad_camera = arguments;
  bad_camera[5] = "cam9:OPENCV";
  EXPECT_EQ(RunCommand(&RunCalibrate, bad_camera), EXIT_FAILURE);
  std::vector<std::string> unknown_option = arguments;
  unknown_option.push_back("--no_such_option");
  EXPECT_EQ(RunCommand(&RunCalibrate, unknown_option), EXIT_FAILURE);
  // Missing correspondence file and missing map.
  std::vector<std::string> missing_file = arguments;
  missing_file[1] = temp_.File("missing.txt");
  EXPECT_EQ(RunCommand(&RunCalibrate, missing_file), EXIT_FAILURE);
  std::vector<std::string> missing_map = arguments;
  missing_map.insert(missing_map.end(), {"--input_path", temp_.File("nomap")});
  EXPECT_EQ(RunCommand(&RunCalibrate, missing_map), EXIT_FAILURE);
  // The known* methods need intrinsics, and say so.
  for (const std::string method : {"known", "known_refine", "known_ra"}) {
    std::vector<std::string> known = arguments;
    known.insert(known.end(), {"--RigCalibrator.method", method});
    ::testing::internal::CaptureStderr();
    EXPECT_EQ(RunCommand(&RunCalibrate, known), EXIT_FAILURE);
    const std::string messages = ::testing::internal::GetCapturedStderr();
    EXPECT_NE(messages.find("method " + method +
                            " needs the intrinsics of camera cam0"),
              std::string::npos)
        << messages;
  }
  EXPECT_FALSE(fs::exists(output));
}

TEST_F(CommandsTest, ExistingOutputIsKeptUnlessOverwrite) {
  const std::string output = temp_.File("out");
  fs::create_directories(output);
  std::ofstream(output + "/keep.txt") << "user data";
  EXPECT_EQ(RunCommand(&RunCalibrate, CalibrateArguments(output)),
            EXIT_FAILURE);
  EXPECT_TRUE(fs::exists(output + "/keep.txt"));
  std::vector<std::string> arguments = CalibrateArguments(output);
  arguments.insert(arguments.end(), {"--overwrite", "1"});
  EXPECT_EQ(RunCommand(&RunCalibrate, arguments), EXIT_SUCCESS);
  EXPECT_TRUE(fs::exists(output + "/rig_config.json"));
}

TEST_F(CommandsTest, KnownMethodWithIntrinsicsFile) {
  const std::string output = temp_.File("known");
  std::vector<std::string> arguments = CalibrateArguments(output);
  arguments.insert(arguments.end(), {"--RigCalibrator.method", "known",
                                     "--RigCalibrator.intrinsics_path",
                                     data_ + "/ground_truth/camchain.yaml"});
  EXPECT_EQ(RunCommand(&RunCalibrate, arguments), EXIT_SUCCESS);
}

// Intrinsics of another image size, and images of one camera folder with
// different sizes, are refused by name.
TEST_F(CommandsTest, ImagesWhoseSizeDiffersFromTheirCameraAreRefused) {
  std::string camchain =
      testing::ReadBytes(data_ + "/ground_truth/camchain.yaml");
  const size_t resolution = camchain.find("resolution: [");
  ASSERT_NE(resolution, std::string::npos);
  const size_t width_begin = resolution + std::string("resolution: [").size();
  const size_t width_end = camchain.find(',', width_begin);
  const std::string width =
      camchain.substr(width_begin, width_end - width_begin);
  camchain.replace(width_begin, width_end - width_begin,
                   std::to_string(std::stoi(width) * 2));
  const std::string wrong_camchain = temp_.File("camchain_2x.yaml");
  std::ofstream(wrong_camchain) << camchain;
  const std::string output = temp_.File("known");
  std::vector<std::string> arguments = CalibrateArguments(output);
  arguments.insert(arguments.end(),
                   {"--RigCalibrator.method", "known",
                    "--RigCalibrator.intrinsics_path", wrong_camchain});
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(RunCommand(&RunCalibrate, arguments), EXIT_FAILURE);
  std::string messages = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(
      messages.find("the intrinsics of camera cam0 (" + wrong_camchain +
                    ") are for " + std::to_string(std::stoi(width) * 2) + "x"),
      std::string::npos)
      << messages;
  EXPECT_NE(messages.find("give intrinsics calibrated at the images' size"),
            std::string::npos)
      << messages;
  EXPECT_FALSE(fs::exists(output));

  std::vector<ImageCorrespondences> images;
  std::string error;
  ASSERT_TRUE(
      ReadCorrespondenceFile(data_ + "/correspondences.txt", &images, &error))
      << error;
  images.back().width += 2;
  const std::string correspondences = temp_.File("resized.txt");
  ASSERT_TRUE(WriteCorrespondenceFile(correspondences, images, &error))
      << error;
  arguments = CalibrateArguments(output);
  arguments[1] = correspondences;
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(RunCommand(&RunCalibrate, arguments), EXIT_FAILURE);
  messages = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(messages.find(" have different sizes (" + images.back().image_name +
                          " is " + std::to_string(images.back().width) + "x"),
            std::string::npos)
      << messages;
  EXPECT_FALSE(fs::exists(output));
}

// known_ra takes the given intrinsics and the robust rig initialization: it
// runs, writes the given intrinsics unchanged, and the rig is accurate.
TEST_F(CommandsTest, KnownRaMethodWithIntrinsicsFile) {
  const std::string output = temp_.File("known_ra");
  std::vector<std::string> arguments = CalibrateArguments(output);
  arguments.insert(arguments.end(), {"--RigCalibrator.method", "known_ra",
                                     "--RigCalibrator.intrinsics_path",
                                     data_ + "/ground_truth/camchain.yaml"});
  ASSERT_EQ(RunCommand(&RunCalibrate, arguments), EXIT_SUCCESS);
  std::ifstream summary_file(output + "/calibration_summary.json");
  EXPECT_EQ(nlohmann::json::parse(summary_file)["method"], "known_ra");
  const nlohmann::json cameras = EvaluatedCameras(output);
  ASSERT_EQ(cameras.size(), 5u);
  for (const nlohmann::json& camera : cameras) {
    EXPECT_LT(camera["rotation_deg"].get<double>(), 0.1);
    EXPECT_LT(camera["center_error"].get<double>(), 0.005);
    // Held fixed at the given (true) intrinsics.
    EXPECT_LT(camera["focal_error_percent"].get<double>(), 1e-6);
  }
}

// Without a frameset in which every camera has an image, known (Inf+K) has
// no rig to start from and says to use known_ra, which then calibrates.
TEST_F(CommandsTest, KnownWithoutCompleteFramesetNamesKnownRa) {
  std::vector<ImageCorrespondences> images;
  std::string error;
  ASSERT_TRUE(
      ReadCorrespondenceFile(data_ + "/correspondences.txt", &images, &error))
      << error;
  // Drop camera (f mod 5)'s image of frameset f: no frameset is complete.
  std::map<std::string, int> frameset_of_file;
  std::vector<ImageCorrespondences> incomplete;
  for (ImageCorrespondences& image : images) {
    const size_t slash = image.image_name.find('/');
    const std::string camera = image.image_name.substr(0, slash);
    const std::string file = image.image_name.substr(slash + 1);
    const int frameset =
        frameset_of_file.emplace(file, frameset_of_file.size()).first->second;
    if (camera != "cam" + std::to_string(frameset % 5)) {
      incomplete.push_back(std::move(image));
    }
  }
  ASSERT_EQ(frameset_of_file.size(), 12u);
  ASSERT_LE(incomplete.size(), 12u * 4);  // the data already misses a few
  const std::string correspondences = temp_.File("incomplete.txt");
  ASSERT_TRUE(WriteCorrespondenceFile(correspondences, incomplete, &error))
      << error;

  for (const std::string method : {"known", "known_ra"}) {
    const std::string output = temp_.File(method);
    std::vector<std::string> arguments = CalibrateArguments(output);
    arguments[1] = correspondences;
    arguments.insert(arguments.end(), {"--RigCalibrator.method", method,
                                       "--RigCalibrator.intrinsics_path",
                                       data_ + "/ground_truth/camchain.yaml"});
    ::testing::internal::CaptureStderr();
    const int exit_code = RunCommand(&RunCalibrate, arguments);
    const std::string messages = ::testing::internal::GetCapturedStderr();
    if (method == "known") {
      EXPECT_EQ(exit_code, EXIT_FAILURE);
      EXPECT_NE(messages.find("use known_ra"), std::string::npos) << messages;
      EXPECT_FALSE(fs::exists(output));
    } else {
      EXPECT_EQ(exit_code, EXIT_SUCCESS) << messages;
    }
  }
}

// The help lists every method of the pipeline under --RigCalibrator.method.
TEST(Calibrate, HelpListsEveryMethod) {
  ::testing::internal::CaptureStdout();
  EXPECT_EQ(RunCommand(&RunCalibrate, {"--help"}), EXIT_SUCCESS);
  const std::string help = ::testing::internal::GetCapturedStdout();
  const size_t option = help.find("--RigCalibrator.method");
  ASSERT_NE(option, std::string::npos) << help;
  const std::string text = help.substr(option, 400);
  for (const std::string method :
       {"1dr", "rd_ra", "rd", "known", "known_refine", "known_ra"}) {
    CalibrationMethod value;
    ASSERT_TRUE(CalibrationMethodFromName(method, &value)) << method;
    EXPECT_NE(text.find(method), std::string::npos) << method << ": " << text;
  }
}

TEST(MapReader, NonColmapFilesAreRejected) {
  testing::ScopedTempDir temp;
  colmap::Reconstruction map;
  std::string error;
  EXPECT_FALSE(ReadMap(temp.File("none"), &map, &error));
  EXPECT_NE(error.find("does not exist"), std::string::npos) << error;
  for (const std::string name : {"cameras.bin", "images.bin", "points3D.bin"}) {
    std::ofstream(temp.File(name)) << "this is not a COLMAP model at all";
  }
  EXPECT_FALSE(ReadMap(temp.path(), &map, &error));
  EXPECT_NE(error.find("not a COLMAP binary model file"), std::string::npos)
      << error;
}

TEST(Evaluate, MissingFilesFail) {
  testing::ScopedTempDir temp;
  EXPECT_EQ(
      RunCommand(&RunEvaluate, {"--reference_path", temp.File("a.json"),
                                "--calibration_path", temp.File("b.yaml")}),
      EXIT_FAILURE);
  EXPECT_EQ(RunCommand(&RunEvaluate, {}), EXIT_FAILURE);
}

}  // namespace commands_test
}  // namespace rig_calibrator
