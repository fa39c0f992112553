// The extended colmap executable (colmap_ext/commands/colmap_main.cc), run as
// a user runs it, next to COLMAP 3.8's own colmap and the standalone
// rig_calibrator: COLMAP's commands give COLMAP's outputs and exit codes,
// `colmap rig_calibrator ...` gives rig_calibrator's, and the help lists both.
#include <colmap/base/database.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "colmap_ext/commands/colmap_help.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace colmap_main_test {

struct Output {
  int exit_code = -1;
  std::string out;
  std::string err;
};

std::string ShellQuoted(const std::string& word) {
  std::string quoted = "'";
  for (const char c : word)
    quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

// Runs `executable arguments...` with stdout and stderr captured.
Output RunExecutable(const std::string& executable,
                     const std::vector<std::string>& arguments) {
  const testing::ScopedTempDir temp;
  std::string command = ShellQuoted(executable);
  for (const std::string& argument : arguments) {
    command += " " + ShellQuoted(argument);
  }
  command += " > " + temp.File("out") + " 2> " + temp.File("err");
  const int status = std::system(command.c_str());
  Output output;
  if (status != -1 && WIFEXITED(status)) output.exit_code = WEXITSTATUS(status);
  output.out = testing::ReadBytes(temp.File("out"));
  output.err = testing::ReadBytes(temp.File("err"));
  return output;
}

std::string Extended() { return testing::BinaryDir() + "/colmap"; }
std::string Standalone() { return testing::BinaryDir() + "/rig_calibrator"; }
std::string Lab() { return testing::BinaryDir() + "/rig_calibrator_lab"; }
std::string Reference() { return COLMAP_REFERENCE_EXECUTABLE; }

// The commands under "Available commands:" of a `colmap help` text.
std::vector<std::string> ListedCommands(const std::string& help) {
  std::vector<std::string> commands;
  std::istringstream lines(help);
  bool in_list = false;
  for (std::string line; std::getline(lines, line);) {
    if (line == "Available commands:") {
      in_list = true;
    } else if (in_list && line.size() > 2 && line.compare(0, 2, "  ") == 0) {
      commands.push_back(line.substr(2));
    } else if (in_list) {
      break;
    }
  }
  return commands;
}

TEST(ColmapMain, HelpIsColmapsWithRigCalibratorAdded) {
  const Output reference = RunExecutable(Reference(), {"help"});
  ASSERT_EQ(reference.exit_code, EXIT_SUCCESS);
  const std::vector<std::string> colmap_commands =
      ListedCommands(reference.out);
  ASSERT_GE(colmap_commands.size(), 40u) << reference.out;
  for (const std::vector<std::string>& arguments :
       std::vector<std::vector<std::string>>{
           {"help"}, {}, {"-h"}, {"--help"}}) {
    const Output extended = RunExecutable(Extended(), arguments);
    EXPECT_EQ(extended.exit_code, EXIT_SUCCESS);
    EXPECT_EQ(extended.out, ExtendColmapHelp(reference.out));
    // The list is COLMAP's with rig_calibrator after rig_bundle_adjuster.
    std::vector<std::string> expected = colmap_commands;
    for (auto it = expected.begin(); it != expected.end(); ++it) {
      if (*it == "rig_bundle_adjuster") {
        expected.insert(it + 1, "rig_calibrator");
        break;
      }
    }
    EXPECT_EQ(ListedCommands(extended.out), expected);
    EXPECT_NE(extended.out.find("  colmap rig_calibrator help\n"),
              std::string::npos);
  }
}

// Every COLMAP command's -h: the same options, text and exit code.
TEST(ColmapMain, EveryColmapCommandsOptionsAreColmaps) {
  const std::vector<std::string> commands =
      ListedCommands(RunExecutable(Reference(), {"help"}).out);
  ASSERT_GE(commands.size(), 40u);
  for (const std::string& command : commands) {
    if (command == "help") continue;
    const Output reference = RunExecutable(Reference(), {command, "-h"});
    const Output extended = RunExecutable(Extended(), {command, "-h"});
    EXPECT_EQ(extended.exit_code, reference.exit_code) << command;
    EXPECT_EQ(extended.out, reference.out) << command;
    EXPECT_EQ(extended.err, reference.err) << command;
  }
  const Output feature_extractor =
      RunExecutable(Extended(), {"feature_extractor", "-h"});
  EXPECT_EQ(feature_extractor.exit_code, EXIT_SUCCESS);
  EXPECT_NE(feature_extractor.out.find("--SiftExtraction.max_num_features"),
            std::string::npos);
}

TEST(ColmapMain, UnknownCommandsAndBadOptionsFailAsInColmap) {
  for (const std::vector<std::string>& arguments :
       std::vector<std::vector<std::string>>{
           {"no_such_command"},
           {"feature_extractor"},
           {"mapper", "--no_such_option", "1"},
           {"gui"}}) {
    const Output reference = RunExecutable(Reference(), arguments);
    const Output extended = RunExecutable(Extended(), arguments);
    EXPECT_EQ(reference.exit_code, EXIT_FAILURE) << arguments[0];
    EXPECT_EQ(extended.exit_code, reference.exit_code) << arguments[0];
    EXPECT_EQ(extended.out, reference.out) << arguments[0];
    EXPECT_EQ(extended.err, reference.err) << arguments[0];
  }
  EXPECT_EQ(RunExecutable(Extended(), {"no_such_command"}).err,
            "ERROR: Command `no_such_command` not recognized. To list the "
            "available commands, run `colmap help`.\n");
}

// A grey-level PGM of Gaussian blobs at random places: SIFT finds hundreds
// of keypoints in it.
void WriteBlobImage(const std::string& path, unsigned seed) {
  const int width = 240, height = 180;
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> x(0, width), y(0, height), sigma(2, 8),
      sign(-1, 1);
  std::vector<double> image(width * height, 128);
  for (int blob = 0; blob < 150; ++blob) {
    const double cx = x(random), cy = y(random), s = sigma(random),
                 a = 100 * sign(random);
    for (int v = 0; v < height; ++v) {
      for (int u = 0; u < width; ++u) {
        const double d2 = (u - cx) * (u - cx) + (v - cy) * (v - cy);
        image[v * width + u] += a * std::exp(-d2 / (2 * s * s));
      }
    }
  }
  std::ofstream file(path, std::ios::binary);
  file << "P5\n" << width << " " << height << "\n255\n";
  for (const double value : image) {
    file.put(
        static_cast<char>(std::lround(std::min(255.0, std::max(0.0, value)))));
  }
}

// The same COLMAP run through both executables writes the same features.
TEST(ColmapMain, FeatureExtractorWritesColmapsFeatures) {
  const testing::ScopedTempDir temp;
  const std::string images = temp.File("images");
  ASSERT_EQ(std::system(("mkdir " + images).c_str()), 0);
  WriteBlobImage(images + "/a.pgm", 1);
  WriteBlobImage(images + "/b.pgm", 2);
  std::vector<colmap::FeatureKeypoints> keypoints[2];
  std::vector<colmap::FeatureDescriptors> descriptors[2];
  const std::string executables[2] = {Reference(), Extended()};
  for (int k = 0; k < 2; ++k) {
    const std::string database = temp.File("database" + std::to_string(k));
    const Output output = RunExecutable(
        executables[k], {"feature_extractor", "--database_path", database,
                         "--image_path", images, "--SiftExtraction.use_gpu",
                         "0", "--SiftExtraction.num_threads", "1"});
    ASSERT_EQ(output.exit_code, EXIT_SUCCESS) << output.err;
    colmap::Database reader(database);
    for (const colmap::Image& image : reader.ReadAllImages()) {
      keypoints[k].push_back(reader.ReadKeypoints(image.ImageId()));
      descriptors[k].push_back(reader.ReadDescriptors(image.ImageId()));
    }
  }
  ASSERT_EQ(keypoints[0].size(), 2u);
  ASSERT_EQ(keypoints[1].size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_GT(keypoints[0][i].size(), 50u);
    ASSERT_EQ(keypoints[1][i].size(), keypoints[0][i].size());
    for (size_t j = 0; j < keypoints[0][i].size(); ++j) {
      EXPECT_EQ(keypoints[1][i][j].x, keypoints[0][i][j].x);
      EXPECT_EQ(keypoints[1][i][j].y, keypoints[0][i][j].y);
      EXPECT_EQ(keypoints[1][i][j].a11, keypoints[0][i][j].a11);
      EXPECT_EQ(keypoints[1][i][j].a21, keypoints[0][i][j].a21);
    }
    EXPECT_TRUE(descriptors[1][i] == descriptors[0][i]);
    std::cout << "image " << i << ": " << keypoints[0][i].size()
              << " SIFT features, identical from both executables\n";
  }
}

TEST(ColmapMain, RigCalibratorIsTheStandaloneCommand) {
  for (const std::vector<std::string>& arguments :
       std::vector<std::vector<std::string>>{
           {"-h"}, {"calibrate", "-h"}, {"evaluate", "-h"}}) {
    const Output standalone = RunExecutable(Standalone(), arguments);
    std::vector<std::string> extended_arguments = {"rig_calibrator"};
    extended_arguments.insert(extended_arguments.end(), arguments.begin(),
                              arguments.end());
    const Output extended = RunExecutable(Extended(), extended_arguments);
    EXPECT_EQ(standalone.exit_code, EXIT_SUCCESS) << arguments[0];
    EXPECT_EQ(extended.exit_code, standalone.exit_code) << arguments[0];
    EXPECT_EQ(extended.out, standalone.out) << arguments[0];
    EXPECT_NE(extended.out.find("--output_path"), std::string::npos);
  }

  // `report` (its only option is --calibration_path).
  const Output standalone_report =
      RunExecutable(Standalone(), {"report", "-h"});
  const Output extended_report =
      RunExecutable(Extended(), {"rig_calibrator", "report", "-h"});
  EXPECT_EQ(standalone_report.exit_code, EXIT_SUCCESS);
  EXPECT_EQ(extended_report.exit_code, EXIT_SUCCESS);
  EXPECT_EQ(extended_report.out, standalone_report.out);
  EXPECT_NE(extended_report.out.find("--calibration_path"), std::string::npos);

  // Its command list, with the usage naming `colmap rig_calibrator`.
  std::string expected = RunExecutable(Standalone(), {"help"}).out;
  for (size_t at = 0;
       (at = expected.find("\n  rig_calibrator ", at)) != std::string::npos;
       at += 3) {
    expected.insert(at + 3, "colmap ");
  }
  for (const std::vector<std::string>& arguments :
       std::vector<std::vector<std::string>>{{"rig_calibrator"},
                                             {"rig_calibrator", "help"}}) {
    const Output extended = RunExecutable(Extended(), arguments);
    EXPECT_EQ(extended.exit_code, EXIT_SUCCESS);
    EXPECT_EQ(extended.out, expected);
  }
  EXPECT_NE(expected.find("  colmap rig_calibrator <command> [options]\n"),
            std::string::npos);

  const Output unknown =
      RunExecutable(Extended(), {"rig_calibrator", "no_such"});
  EXPECT_EQ(unknown.exit_code, EXIT_FAILURE);
  EXPECT_EQ(unknown.err,
            "ERROR: unknown command `no_such`; run `colmap rig_calibrator "
            "help` for the list.\n");
}

// The lab's commands are rig_calibrator_lab's, not the shipped executables'.
TEST(ColmapMain, LabCommandsAreTheLabs) {
  const std::vector<std::string> lab_commands = {"synthetic",
                                                 "render",
                                                 "benchmark",
                                                 "benchmark_runtime",
                                                 "benchmark_localization",
                                                 "benchmark_colmap_rig_ba"};
  const std::string lab_help = RunExecutable(Lab(), {"help"}).out;
  const std::string help = RunExecutable(Standalone(), {"help"}).out;
  for (const std::string& command : lab_commands) {
    EXPECT_NE(lab_help.find("\n  " + command + " "), std::string::npos)
        << command;
    EXPECT_EQ(help.find("\n  " + command + " "), std::string::npos) << command;
    const Output lab = RunExecutable(Lab(), {command, "-h"});
    EXPECT_EQ(lab.exit_code, EXIT_SUCCESS) << command;
    EXPECT_NE(lab.out.find("rig_calibrator_lab " + command + ": "),
              std::string::npos)
        << command;
    EXPECT_EQ(RunExecutable(Standalone(), {command, "-h"}).exit_code,
              EXIT_FAILURE)
        << command;
    EXPECT_EQ(
        RunExecutable(Extended(), {"rig_calibrator", command, "-h"}).exit_code,
        EXIT_FAILURE)
        << command;
  }
}

// A sub-command's outputs through colmap are the standalone's, byte for byte
// (`evaluate` of a synthetic rig's ground truth in its two formats).
TEST(ColmapMain, RigCalibratorEvaluateWritesTheSameErrors) {
  const testing::ScopedTempDir temp;
  ASSERT_EQ(RunExecutable(Lab(), {"synthetic", "--num_framesets", "4", "--seed",
                                  "3", "--output_path", temp.File("data")})
                .exit_code,
            EXIT_SUCCESS);
  const std::vector<std::string> options = {
      "evaluate",
      "--reference_path",
      temp.File("data/ground_truth/camchain.yaml"),
      "--calibration_path",
      temp.File("data/ground_truth/rig_config.json"),
      "--output_path"};
  std::vector<std::string> standalone = options;
  standalone.push_back(temp.File("standalone.json"));
  std::vector<std::string> extended = {"rig_calibrator"};
  extended.insert(extended.end(), options.begin(), options.end());
  extended.push_back(temp.File("extended.json"));
  const Output standalone_output = RunExecutable(Standalone(), standalone);
  const Output extended_output = RunExecutable(Extended(), extended);
  ASSERT_EQ(standalone_output.exit_code, EXIT_SUCCESS);
  ASSERT_EQ(extended_output.exit_code, EXIT_SUCCESS);
  EXPECT_EQ(extended_output.out, standalone_output.out);
  const std::string bytes = testing::ReadBytes(temp.File("standalone.json"));
  EXPECT_FALSE(bytes.empty());
  EXPECT_EQ(testing::ReadBytes(temp.File("extended.json")), bytes);
}

}  // namespace colmap_main_test
}  // namespace rig_calibrator
