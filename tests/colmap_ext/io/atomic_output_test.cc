#include "colmap_ext/io/atomic_output.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "tests/testing.h"

namespace rig_calibrator {
namespace atomic_output_test {

namespace fs = std::filesystem;

size_t NumEntries(const std::string& folder) {
  return std::distance(fs::directory_iterator(folder),
                       fs::directory_iterator());
}

bool WriteTwoFiles(const std::string& folder, std::string* error) {
  std::ofstream(folder + "/a.txt") << "a";
  return WriteFileAtomically(folder + "/b.txt", "b", error);
}

TEST(AtomicOutput, FileIsReplacedWhole) {
  testing::ScopedTempDir dir;
  const std::string path = dir.File("f.txt");
  std::string error;
  ASSERT_TRUE(WriteFileAtomically(path, "first", &error)) << error;
  ASSERT_TRUE(WriteFileAtomically(path, "second", &error)) << error;
  EXPECT_EQ(testing::ReadBytes(path), "second");
  EXPECT_EQ(NumEntries(dir.path()), 1u);
  EXPECT_FALSE(WriteFileAtomically(dir.File("missing/f.txt"), "x", &error));
}

TEST(AtomicOutput, FailureMidwayLeavesNothing) {
  testing::ScopedTempDir dir;
  const std::string output = dir.File("out");
  std::string error;
  const bool written = WriteFolderAtomically(
      output, OutputFolderOptions(),
      [](const std::string& folder, std::string* error) {
        EXPECT_TRUE(WriteTwoFiles(folder, error));
        EXPECT_TRUE(fs::exists(folder + "/b.txt"));
        *error = "disk full";
        return false;
      },
      &error);
  EXPECT_FALSE(written);
  EXPECT_EQ(error, "disk full");
  EXPECT_EQ(NumEntries(dir.path()), 0u);

  // An exception midway is passed on, and leaves nothing either.
  EXPECT_THROW(WriteFolderAtomically(
                   output, OutputFolderOptions(),
                   [](const std::string& folder, std::string* error) -> bool {
                     WriteTwoFiles(folder, error);
                     throw std::runtime_error("crash");
                   },
                   &error),
               std::runtime_error);
  EXPECT_EQ(NumEntries(dir.path()), 0u);
}

TEST(AtomicOutput, FolderAppearsWhole) {
  testing::ScopedTempDir dir;
  const std::string output = dir.File("out");
  std::string error;
  ASSERT_TRUE(WriteFolderAtomically(output, OutputFolderOptions(),
                                    WriteTwoFiles, &error))
      << error;
  EXPECT_EQ(testing::ReadBytes(output + "/a.txt"), "a");
  EXPECT_EQ(testing::ReadBytes(output + "/b.txt"), "b");
  EXPECT_EQ(NumEntries(dir.path()), 1u);

  // Non-empty: refused, then replaced with overwrite.
  EXPECT_FALSE(WriteFolderAtomically(output, OutputFolderOptions(),
                                     WriteTwoFiles, &error));
  EXPECT_NE(error.find("pass --overwrite"), std::string::npos) << error;
  std::ofstream(output + "/old.txt") << "old";
  OutputFolderOptions overwrite;
  overwrite.overwrite = true;
  ASSERT_TRUE(WriteFolderAtomically(output, overwrite, WriteTwoFiles, &error))
      << error;
  EXPECT_FALSE(fs::exists(output + "/old.txt"));
  EXPECT_EQ(NumEntries(dir.path()), 1u);

  // A file in the way, or a missing parent folder.
  std::ofstream(dir.File("file")) << "x";
  EXPECT_FALSE(WriteFolderAtomically(dir.File("file"), overwrite, WriteTwoFiles,
                                     &error));
  EXPECT_NE(error.find("is not a folder"), std::string::npos);
  EXPECT_FALSE(WriteFolderAtomically(dir.File("no/out"), overwrite,
                                     WriteTwoFiles, &error));
  EXPECT_NE(error.find("does not exist"), std::string::npos);
}

// The old output is only replaced once the new one is complete: a failing
// writer leaves it as it was, even with overwrite. An empty folder in the way
// needs no overwrite.
TEST(AtomicOutput, FailedOverwriteKeepsTheOldOutput) {
  testing::ScopedTempDir dir;
  const std::string output = dir.File("out");
  fs::create_directories(output);
  std::string error;
  ASSERT_TRUE(WriteFolderAtomically(output, OutputFolderOptions(),
                                    WriteTwoFiles, &error))
      << error;
  std::ofstream(output + "/old.txt") << "old";
  OutputFolderOptions overwrite;
  overwrite.overwrite = true;
  EXPECT_FALSE(WriteFolderAtomically(
      output, overwrite,
      [](const std::string& folder, std::string* error) {
        WriteTwoFiles(folder, error);
        *error = "disk full";
        return false;
      },
      &error));
  EXPECT_EQ(testing::ReadBytes(output + "/old.txt"), "old");
  EXPECT_EQ(testing::ReadBytes(output + "/a.txt"), "a");
  EXPECT_EQ(NumEntries(output), 3u);
  EXPECT_EQ(NumEntries(dir.path()), 1u);
}

// Another process creating or filling the output folder while this one
// writes (two runs into one output): the later rename fails, the other's
// output stays as it is, nothing is mixed and no temporary folder is left.
TEST(AtomicOutput, OutputCreatedMeanwhileIsNotReplaced) {
  for (const bool output_existed_empty : {false, true}) {
    testing::ScopedTempDir dir;
    const std::string output = dir.File("out");
    if (output_existed_empty) fs::create_directories(output);
    std::string error;
    EXPECT_FALSE(WriteFolderAtomically(
        output, OutputFolderOptions(),
        [&](const std::string& folder, std::string* error) {
          fs::create_directories(output);
          std::ofstream(output + "/other.txt") << "other run";
          return WriteTwoFiles(folder, error);
        },
        &error));
    EXPECT_NE(error.find("was created or filled by another process while this "
                         "run was writing (two runs into the same output?)"),
              std::string::npos)
        << error;
    EXPECT_EQ(testing::ReadBytes(output + "/other.txt"), "other run");
    EXPECT_EQ(NumEntries(output), 1u);
    EXPECT_EQ(NumEntries(dir.path()), 1u);
  }
}

// A pid that no process has: a child that has exited and been reaped.
pid_t DeadProcessId() {
  const pid_t child = fork();
  if (child == 0) _exit(0);
  waitpid(child, nullptr, 0);
  return child;
}

// Temporary folders of killed runs (kill -9) are removed by the next run
// into the same output; those of running processes are kept.
TEST(AtomicOutput, StaleTemporaryFoldersOfDeadRunsAreRemoved) {
  testing::ScopedTempDir dir;
  const std::string dead = std::to_string(DeadProcessId());
  const std::string alive = std::to_string(getppid());
  for (const std::string& name :
       {".out.tmp-" + dead + "-12345", ".out.old-" + dead + "-7",
        ".out.tmp-" + alive + "-1", ".other.tmp-" + dead + "-1",
        ".out.tmp-x" + dead + "-1"}) {
    fs::create_directories(dir.File(name));
    std::ofstream(dir.File(name) + "/partial.txt") << "partial";
  }
  std::string error;
  ::testing::internal::CaptureStdout();
  ASSERT_TRUE(WriteFolderAtomically(dir.File("out"), OutputFolderOptions(),
                                    WriteTwoFiles, &error))
      << error;
  const std::string log = ::testing::internal::GetCapturedStdout();
  EXPECT_NE(log.find(".out.tmp-" + dead +
                     "-12345, left by an interrupted "
                     "run (its process no longer exists)"),
            std::string::npos)
      << log;
  EXPECT_FALSE(fs::exists(dir.File(".out.tmp-" + dead + "-12345")));
  EXPECT_FALSE(fs::exists(dir.File(".out.old-" + dead + "-7")));
  EXPECT_TRUE(fs::exists(dir.File(".out.tmp-" + alive + "-1")));
  EXPECT_TRUE(fs::exists(dir.File(".other.tmp-" + dead + "-1")));
  EXPECT_TRUE(fs::exists(dir.File(".out.tmp-x" + dead + "-1")));
  EXPECT_EQ(NumEntries(dir.path()), 4u);

  // The same for the temporary file of a single file.
  std::ofstream(dir.File(".f.txt.tmp-" + dead + "-3")) << "partial";
  ASSERT_TRUE(WriteFileAtomically(dir.File("f.txt"), "f", &error)) << error;
  EXPECT_FALSE(fs::exists(dir.File(".f.txt.tmp-" + dead + "-3")));
  EXPECT_EQ(NumEntries(dir.path()), 5u);
}

// The early check of the command: a read-only file system is reported
// before any work (here a missing parent and a non-empty folder; the
// read-only case needs a mount: output_faults_test.sh).
TEST(AtomicOutput, UsableCheckGivesTheWritersMessages) {
  testing::ScopedTempDir dir;
  std::string error;
  EXPECT_TRUE(
      CheckOutputFolderUsable(dir.File("out"), OutputFolderOptions(), &error));
  EXPECT_FALSE(CheckOutputFolderUsable(dir.File("no/out"),
                                       OutputFolderOptions(), &error));
  EXPECT_NE(error.find("does not exist"), std::string::npos) << error;
  fs::create_directories(dir.File("full"));
  std::ofstream(dir.File("full/a.txt")) << "a";
  EXPECT_FALSE(
      CheckOutputFolderUsable(dir.File("full"), OutputFolderOptions(), &error));
  EXPECT_NE(error.find("pass --overwrite"), std::string::npos) << error;
  EXPECT_EQ(NumEntries(dir.path()), 1u);
}

TEST(AtomicOutput, OutputMustNotOverlapInputs) {
  testing::ScopedTempDir dir;
  fs::create_directories(dir.File("map/sparse/0"));
  OutputFolderOptions options;
  options.overwrite = true;
  options.input_paths = {dir.File("map/sparse/0"), dir.File("images")};
  std::string error;
  for (const std::string& output :
       {dir.File("map/sparse/0"), dir.File("map/sparse/0/"),
        dir.File("map/sparse/0/out"), dir.File("map"),
        dir.File("images/../map/sparse")}) {
    EXPECT_FALSE(WriteFolderAtomically(output, options, WriteTwoFiles, &error))
        << output;
    EXPECT_NE(error.find("overlaps the input path"), std::string::npos);
  }
  EXPECT_TRUE(fs::exists(dir.File("map/sparse/0")));
  EXPECT_TRUE(WriteFolderAtomically(dir.File("map/sparse/1"), options,
                                    WriteTwoFiles, &error))
      << error;
}

}  // namespace atomic_output_test
}  // namespace rig_calibrator
