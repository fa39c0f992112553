// `rig_calibrator report --calibration_path OUT` (RunReport; the dispatcher
// runs it in report_browser_test.sh and colmap_main_test.cc): rebuilds
// report.html as the calibration wrote it, leaves the folder otherwise
// unchanged, and fails with a message naming the folder.
#include <gtest/gtest.h>

#include <boost/filesystem.hpp>
#include <string>
#include <vector>

#include "colmap_ext/commands/commands.h"
#include "tests/colmap_ext/report/report_testing.h"

namespace rig_calibrator {
namespace report_command_test {

int RunReportCommand(const std::vector<std::string>& arguments) {
  std::vector<std::string> args = {"rig_calibrator report"};
  args.insert(args.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  return RunReport(static_cast<int>(argv.size()), argv.data());
}

TEST(ReportCommand, RebuildsTheReportAndChangesNothingElse) {
  const testing::Scene scene = testing::MakeScene();
  testing::ScopedTempDir dir;
  const std::string output = dir.File("out");
  std::string error;
  ASSERT_TRUE(testing::WriteSceneOutput(scene, output, true, &error)) << error;
  const auto written = testing::SnapshotFolder(output);
  boost::filesystem::remove(output + "/" + kReportFile);
  ::testing::internal::CaptureStdout();
  EXPECT_EQ(RunReportCommand({"--calibration_path", output}), EXIT_SUCCESS);
  const std::string out = ::testing::internal::GetCapturedStdout();
  EXPECT_NE(out.find("Report: " + output + "/report.html"), std::string::npos)
      << out;
  EXPECT_EQ(testing::SnapshotFolder(output), written);
  EXPECT_EQ(testing::ListFolder(dir.path()), std::set<std::string>{"out"});
}

TEST(ReportCommand, BadFolderIsAnErrorNamingIt) {
  testing::ScopedTempDir dir;
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(RunReportCommand({"--calibration_path", dir.File("missing")}),
            EXIT_FAILURE);
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("no report written: no calibration output folder at " +
                     dir.File("missing")),
            std::string::npos)
      << err;
  EXPECT_TRUE(testing::ListFolder(dir.path()).empty());
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(RunReportCommand({}), EXIT_FAILURE);
  EXPECT_NE(::testing::internal::GetCapturedStderr().find("calibration_path"),
            std::string::npos);
}

}  // namespace report_command_test
}  // namespace rig_calibrator
