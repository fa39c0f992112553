// The small synthetic calibration that the whole-pipeline fuzz target
// (pipeline_fuzzer.cc) runs end to end, and its input files: a 3-camera
// ring rig (OPENCV), 6 framesets of 40 correspondences per image, a map of 6
// images as a COLMAP model (text and binary), and the true intrinsics as
// rig_config.json and camchain.yaml (for method `known`). One run takes well
// under a second in the fuzz build.
#pragma once

#include <string>
#include <vector>

namespace rig_calibrator {
namespace fuzz {

// The input files that the fuzz target replaces, one per selector value (the
// input's first byte modulo their count), as paths relative to the case's
// folder.
const std::vector<std::string>& PipelineCaseFiles();

// Writes the case into `folder` (created): txt/ and bin/ (the map),
// correspondences.txt, rig_config.json, camchain.yaml. Aborts if a file
// cannot be written (a fuzzing set-up error).
void WritePipelineCase(const std::string& folder);

// The command line of a calibration with the file `selected` (an entry of
// PipelineCaseFiles) of the case in `folder`, into `output`: the map of the
// selected type (text by default), method `known` with the selected
// intrinsics file.
std::vector<std::string> PipelineArguments(const std::string& folder,
                                           const std::string& selected,
                                           const std::string& output);

}  // namespace fuzz
}  // namespace rig_calibrator
