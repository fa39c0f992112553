// `rig_calibrator_lab synthetic` with the time model, in process: the
// options reach the generator (milliseconds and microseconds converted to
// seconds) and ground_truth/time_model.json holds the true offsets, line
// delays and frameset times; bad option text and time options without a
// frameset rate fail with a message.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "colmap_ext/lab_commands/lab_commands.h"
#include "tests/colmap_ext/colmap_testing.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace synthetic_command_test {

using testing::RunCommand;

std::vector<std::string> SmallTimedArguments(const std::string& output_path) {
  return {"--output_path",    output_path, "--num_framesets",   "4",
          "--points_per_image", "20",      "--frameset_rate_hz", "5"};
}

TEST(SyntheticCommand, WritesTheTimeModel) {
  testing::ScopedTempDir temp;
  std::vector<std::string> arguments = SmallTimedArguments(temp.File("data"));
  arguments.insert(arguments.end(),
                   {"--max_time_offset_ms", "50", "--line_delay_us", "20,30"});
  ::testing::internal::CaptureStdout();
  ASSERT_EQ(RunCommand(&RunSynthetic, arguments), EXIT_SUCCESS);
  ::testing::internal::GetCapturedStdout();
  std::ifstream file(temp.File("data/ground_truth/time_model.json"));
  ASSERT_TRUE(file.good());
  const nlohmann::json json = nlohmann::json::parse(file);
  EXPECT_EQ(json["frameset_rate_hz"], 5.0);
  EXPECT_EQ(json["reference_camera"], "cam0");
  ASSERT_EQ(json["cameras"].size(), 5);
  EXPECT_EQ(json["cameras"][0]["time_offset_s"], 0.0);
  double largest_offset = 0;
  for (const nlohmann::json& camera : json["cameras"]) {
    const double offset = camera["time_offset_s"];
    const double line_delay = camera["line_delay_s"];
    EXPECT_LE(std::abs(offset), 0.05);
    largest_offset = std::max(largest_offset, std::abs(offset));
    EXPECT_GE(line_delay, 20e-6);
    EXPECT_LE(line_delay, 30e-6);
    EXPECT_EQ(camera["rows"], 480);
  }
  EXPECT_GT(largest_offset, 0.005);
  ASSERT_EQ(json["framesets"].size(), 4);
  EXPECT_EQ(json["framesets"][3]["name"], "000003");
  EXPECT_DOUBLE_EQ(json["framesets"][3]["time_s"].get<double>(), 0.6);
}

TEST(SyntheticCommand, GivenPerCameraValuesAndBadText) {
  testing::ScopedTempDir temp;
  std::vector<std::string> given = SmallTimedArguments(temp.File("given"));
  given.insert(given.end(), {"--camera_time_offsets_ms", "0,10,-20,30,-40",
                             "--camera_line_delays_us", "0,25,0,30,20"});
  ::testing::internal::CaptureStdout();
  ASSERT_EQ(RunCommand(&RunSynthetic, given), EXIT_SUCCESS);
  ::testing::internal::GetCapturedStdout();
  std::ifstream file(temp.File("given/ground_truth/time_model.json"));
  const nlohmann::json json = nlohmann::json::parse(file);
  EXPECT_DOUBLE_EQ(json["cameras"][4]["time_offset_s"].get<double>(), -0.04);
  EXPECT_DOUBLE_EQ(json["cameras"][3]["line_delay_s"].get<double>(), 30e-6);

  // Each bad case (extra arguments; the untimed one drops the frameset
  // rate) and the words its message must hold.
  const std::vector<std::pair<std::vector<std::string>, std::string>> bad = {
      {{"--line_delay_us", "1,2,3"}, "--line_delay_us must be MIN,MAX"},
      {{"--line_delay_us", "20us"}, "--line_delay_us must be MIN,MAX"},
      {{"--camera_time_offsets_ms", "0,1,,2"},
       "--camera_time_offsets_ms must be a comma-separated list"},
      {{"--camera_line_delays_us", "a"},
       "--camera_line_delays_us must be a comma-separated list"},
      {{"--camera_time_offsets_ms", "0,1,2"},
       "time_offsets_s needs one finite offset per camera (5)"},
      {{"--max_time_offset_ms", "50"}, "need the time model"},
  };
  for (const auto& [extra, expected] : bad) {
    std::vector<std::string> arguments = SmallTimedArguments(temp.File("bad"));
    if (expected == "need the time model") arguments.resize(6);
    arguments.insert(arguments.end(), extra.begin(), extra.end());
    ::testing::internal::CaptureStderr();
    EXPECT_NE(RunCommand(&RunSynthetic, arguments), EXIT_SUCCESS) << expected;
    const std::string message = ::testing::internal::GetCapturedStderr();
    EXPECT_NE(message.find(expected), std::string::npos)
        << "expected '" << expected << "' in: " << message;
  }
}

}  // namespace synthetic_command_test
}  // namespace rig_calibrator
