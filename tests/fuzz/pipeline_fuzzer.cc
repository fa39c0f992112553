// Whole-pipeline fuzz target: the calibrate command (RunCalibrate, without
// the top-level handler, so that an escaping exception is a crash) end to
// end on a small synthetic case (pipeline_case.h) — the map's readers and
// its consistency check, the calibration stages, the output writer — with
// one input file replaced by the fuzzed bytes: the input's first byte picks
// the file (the text or binary map's cameras, images or points3D, the
// correspondence file, rig_config.json or camchain.yaml as known
// intrinsics), the rest is its content. The command must end with exit code
// 0 or 1 and leave no partial output: no output folder, or a complete one (a
// run whose cameras are flagged invalid writes its output and exits with 1),
// and no temporary folder.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "colmap_ext/commands/commands.h"
#include "tests/fuzz/fuzz_files.h"
#include "tests/fuzz/pipeline_case.h"

namespace {

namespace fs = std::filesystem;
using namespace rig_calibrator;

// The case's valid files in <scratch>/valid, the run's in <scratch>/case.
const std::string& CaseFolder() {
  static const std::string folder = [] {
    const std::string valid = fuzz::ScratchFolder() + "/valid";
    const std::string run = fuzz::ScratchFolder() + "/case";
    fuzz::WritePipelineCase(valid);
    fuzz::WritePipelineCase(run);
    return run;
  }();
  return folder;
}

int RunCalibrateWith(const std::vector<std::string>& arguments) {
  std::vector<std::string> strings = {"rig_calibrator"};
  strings.insert(strings.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& argument : strings) argv.push_back(argument.data());
  return RunCalibrate(static_cast<int>(argv.size()), argv.data());
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // The command's progress and messages: the sanitizers and libFuzzer
  // report through their own writes to stderr.
  std::cout.setstate(std::ios::badbit);
  std::cerr.setstate(std::ios::badbit);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::vector<std::string>& files = fuzz::PipelineCaseFiles();
  const std::string& selected = files[data[0] % files.size()];
  const std::string folder = CaseFolder();
  fuzz::WriteScratchFile("case/" + selected, data + 1, size - 1);
  const std::string output = fuzz::ScratchFolder() + "/out";
  const int exit_code =
      RunCalibrateWith(fuzz::PipelineArguments(folder, selected, output));
  if (exit_code != EXIT_SUCCESS && exit_code != EXIT_FAILURE) std::abort();
  if (exit_code == EXIT_SUCCESS && !fs::exists(output)) std::abort();
  // report.html is written last into the temporary folder, before it is
  // renamed into place (atomic_output.h).
  if (fs::exists(output) && !fs::exists(output + "/report.html")) std::abort();
  for (const auto& entry : fs::directory_iterator(fuzz::ScratchFolder())) {
    if (entry.path().filename().string().rfind(".out.tmp", 0) == 0) {
      std::abort();
    }
  }
  fs::remove_all(output);
  fuzz::CopyFile(fuzz::ScratchFolder() + "/valid/" + selected,
                 folder + "/" + selected);
  return 0;
}
