// Output that appears completely or not at all: files are written to a
// temporary sibling and renamed into place, so a crash or an error midway
// never leaves a partial file or folder behind.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace rig_calibrator {

// Writes `contents` to `path` through a temporary file in the same folder
// and a rename (atomic on POSIX file systems). Temporary files of `path`
// left by killed runs are removed first (as for folders, below).
bool WriteFileAtomically(const std::string& path, const std::string& contents,
                         std::string* error);
// The same with the contents in pieces, written in order.
bool WriteFileAtomically(const std::string& path,
                         const std::vector<std::string_view>& pieces,
                         std::string* error);

struct OutputFolderOptions {
  // Replace an existing non-empty output folder (otherwise that is an error).
  bool overwrite = false;
  // Inputs of the run: the output folder may be neither one of them, nor
  // inside one, nor contain one (overwriting would delete it).
  std::vector<std::string> input_paths;
};

// The checks WriteFolderAtomically makes before writing (the output overlaps
// no input, is an empty folder or absent, or overwrite is set), and that the
// folder holding it is writable, with the message it would give: to fail
// before a long computation rather than after it.
bool CheckOutputFolderUsable(const std::string& output_path,
                             const OutputFolderOptions& options,
                             std::string* error);

// Fills the folder `output_path` through `write_contents`, which gets a fresh
// temporary sibling folder to write into. Only if it returns true is the
// temporary folder renamed to `output_path`; otherwise (or on any file system
// error) the temporary folder is removed and `output_path` is left as it was.
// The rename fails (and nothing is replaced) if another process created or
// filled `output_path` meanwhile, so of two runs into one output one wins;
// with overwrite the old and new folders are swapped in one step
// (RENAME_EXCHANGE). Temporary siblings left by killed runs (whose process
// no longer exists) are removed first, with a line on stdout.
bool WriteFolderAtomically(
    const std::string& output_path, const OutputFolderOptions& options,
    const std::function<bool(const std::string& folder, std::string* error)>&
        write_contents,
    std::string* error);

}  // namespace rig_calibrator
