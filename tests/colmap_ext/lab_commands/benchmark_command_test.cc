// The benchmark command (the paper's experiments) in process.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "colmap_ext/lab_commands/lab_commands.h"
#include "tests/colmap_ext/colmap_testing.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace benchmark_command_test {

using testing::RunCommand;

// --methods chooses the benchmark's methods: the table has a row for each
// given method and none for the default ones; an unknown name fails.
TEST(Benchmark, MethodsOptionSelectsTheMethods) {
  testing::ScopedTempDir temp;
  const std::string table = temp.File("table.md");
  const std::vector<std::string> small = {
      "--num_sequences",          "2", "--recording_framesets", "16",
      "--framesets_per_sequence", "6", "--output_path",         table};
  std::vector<std::string> arguments = small;
  arguments.insert(arguments.end(), {"--methods", "known_ra,1dr"});
  ::testing::internal::CaptureStdout();
  ASSERT_EQ(RunCommand(&RunBenchmark, arguments), EXIT_SUCCESS);
  ::testing::internal::GetCapturedStdout();
  std::ifstream file(table);
  std::vector<std::string> rows;
  for (std::string line; std::getline(file, line);) {
    if (line.rfind("| ", 0) != 0) continue;
    const size_t end = line.find(" |", 2);
    rows.push_back(line.substr(2, end - 2));
  }
  auto count = [&rows](const std::string& name) {
    return std::count(rows.begin(), rows.end(), name);
  };
  EXPECT_EQ(count("known_ra"), 1) << ::testing::PrintToString(rows);
  EXPECT_EQ(count("1dr"), 1) << ::testing::PrintToString(rows);
  EXPECT_EQ(count("rd"), 0) << ::testing::PrintToString(rows);
  EXPECT_EQ(count("rd_ra"), 0) << ::testing::PrintToString(rows);

  arguments = small;
  arguments.insert(arguments.end(), {"--methods", "known,nonsense"});
  ::testing::internal::CaptureStderr();
  EXPECT_NE(RunCommand(&RunBenchmark, arguments), EXIT_SUCCESS);
  EXPECT_NE(::testing::internal::GetCapturedStderr().find(
                "unknown method nonsense in --methods"),
            std::string::npos);
}

}  // namespace benchmark_command_test
}  // namespace rig_calibrator
