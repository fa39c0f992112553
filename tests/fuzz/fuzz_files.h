// Files for the fuzz targets: the readers take paths, so every input is
// written to a file in a folder of its own (one per process, removed at
// exit), which libFuzzer's parallel jobs do not share.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace rig_calibrator {
namespace fuzz {

// The process's scratch folder, created on first use.
const std::string& ScratchFolder();

// Writes `size` bytes to ScratchFolder()/name and returns the path.
std::string WriteScratchFile(const std::string& name, const uint8_t* data,
                             size_t size);
inline std::string WriteScratchFile(const std::string& name,
                                    const std::string& bytes) {
  return WriteScratchFile(name, reinterpret_cast<const uint8_t*>(bytes.data()),
                          bytes.size());
}

// Copies the file `from` to `to` (overwriting it) through streams. Not
// std::filesystem::copy_file: its sendfile() fails with EINTR when
// libFuzzer's timer signal (-timeout) arrives during the copy, which ended a
// model_fuzzer run with an uncaught filesystem_error.
void CopyFile(const std::string& from, const std::string& to);

}  // namespace fuzz
}  // namespace rig_calibrator
