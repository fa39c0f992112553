// The commands' top-level handler (guarded_run.h): an exception that escapes
// a command becomes one line "ERROR: internal error: ..." on stderr and
// EXIT_FAILURE instead of std::terminate's abort.
#include "colmap_ext/commands/guarded_run.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace rig_calibrator {
namespace guarded_run_test {

// Runs `command` through RunGuarded; returns its exit code and stderr.
std::pair<int, std::string> Guarded(const std::function<int()>& command) {
  ::testing::internal::CaptureStderr();
  const int exit_code = RunGuarded(command);
  const std::string messages = ::testing::internal::GetCapturedStderr();
  std::cout << messages << std::flush;  // for the test log
  return {exit_code, messages};
}

TEST(RunGuarded, ReturnsTheCommandsExitCode) {
  EXPECT_EQ(Guarded([] { return 0; }), std::make_pair(0, std::string()));
  EXPECT_EQ(Guarded([] { return 3; }), std::make_pair(3, std::string()));
}

// The exception of issue 31: unordered_map::at on an id the map lacks.
TEST(RunGuarded, StandardExceptionBecomesOneErrorLine) {
  const auto [exit_code, messages] = Guarded([]() -> int {
    const std::unordered_map<int, int> empty;
    return empty.at(31);
  });
  EXPECT_EQ(exit_code, EXIT_FAILURE);
  EXPECT_EQ(messages.rfind("ERROR: internal error: ", 0), 0u) << messages;
  EXPECT_NE(messages.find("unordered_map::at"), std::string::npos) << messages;
  EXPECT_EQ(std::count(messages.begin(), messages.end(), '\n'), 1)
      << messages;
}

TEST(RunGuarded, ExceptionOfAnyTypeBecomesOneErrorLine) {
  const auto [exit_code, messages] = Guarded([]() -> int { throw 42; });
  EXPECT_EQ(exit_code, EXIT_FAILURE);
  EXPECT_EQ(messages.rfind("ERROR: internal error: an exception of unknown "
                           "type",
                           0),
            0u)
      << messages;
  EXPECT_EQ(std::count(messages.begin(), messages.end(), '\n'), 1)
      << messages;
}

}  // namespace guarded_run_test
}  // namespace rig_calibrator
