#include "colmap_ext/io/atomic_output.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <system_error>

namespace rig_calibrator {
namespace {

namespace fs = std::filesystem;

// A name for a temporary sibling of `path` that no other process picks:
// hidden, tagged with the process id and random digits.
fs::path TemporarySibling(const fs::path& path, const std::string& tag) {
  static thread_local std::mt19937_64 generator(std::random_device{}());
  const fs::path parent =
      path.parent_path().empty() ? fs::path(".") : path.parent_path();
  for (;;) {
    const fs::path candidate =
        parent / ("." + path.filename().string() + "." + tag + "-" +
                  std::to_string(getpid()) + "-" +
                  std::to_string(generator() % 1000000000));
    std::error_code ignored;
    if (!fs::exists(candidate, ignored)) {
      return candidate;
    }
  }
}

// `path` made absolute and free of "..", symlinks resolved where it exists.
fs::path Normalized(const std::string& path) {
  std::error_code code;
  fs::path normalized = fs::weakly_canonical(fs::absolute(path), code);
  if (code) {
    normalized = fs::absolute(path).lexically_normal();
  }
  // "a/b/" and "a/b" name the same folder.
  if (!normalized.has_filename() && normalized.has_parent_path()) {
    normalized = normalized.parent_path();
  }
  return normalized;
}

// True if `inner` is `outer` or lies inside it.
bool IsWithin(const fs::path& inner, const fs::path& outer) {
  auto inner_it = inner.begin();
  for (auto outer_it = outer.begin(); outer_it != outer.end(); ++outer_it) {
    if (inner_it == inner.end() || *inner_it != *outer_it) {
      return false;
    }
    ++inner_it;
  }
  return true;
}

}  // namespace

bool WriteFileAtomically(const std::string& path, const std::string& contents,
                         std::string* error) {
  const fs::path temporary = TemporarySibling(path, "tmp");
  {
    std::ofstream file(temporary, std::ios::binary | std::ios::trunc);
    if (!file) {
      *error = "cannot create " + temporary.string();
      return false;
    }
    file.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    file.close();
    if (!file) {
      std::error_code ignored;
      fs::remove(temporary, ignored);
      *error = "cannot write " + temporary.string();
      return false;
    }
  }
  std::error_code code;
  fs::rename(temporary, path, code);
  if (code) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    *error = "cannot rename " + temporary.string() + " to " + path + ": " +
             code.message();
    return false;
  }
  return true;
}

namespace {

void RemoveFolder(const fs::path& folder) {
  std::error_code ignored;
  fs::remove_all(folder, ignored);
}

// The output may not overlap an input, must be a folder that is empty (or
// overwrite is set) or not exist, in an existing folder.
bool CheckOutputFolder(const std::string& output_path,
                       const OutputFolderOptions& options, fs::path* normalized,
                       bool* exists, std::string* error) {
  *normalized = Normalized(output_path);
  const fs::path& output = *normalized;
  for (const std::string& input_path : options.input_paths) {
    if (input_path.empty()) continue;
    const fs::path input = Normalized(input_path);
    if (IsWithin(output, input) || IsWithin(input, output)) {
      *error = "the output path " + output_path + " overlaps the input path " +
               input_path + "; choose an output folder outside the inputs";
      return false;
    }
  }

  std::error_code code;
  *exists = fs::exists(output, code);
  if (*exists) {
    if (!fs::is_directory(output, code)) {
      *error = "the output path " + output_path + " exists and is not a folder";
      return false;
    }
    if (!fs::is_empty(output, code) && !options.overwrite) {
      *error = "the output folder " + output_path +
               " exists and is not empty; remove it, choose another one or "
               "pass --overwrite";
      return false;
    }
  } else if (!output.parent_path().empty() &&
             !fs::is_directory(output.parent_path(), code)) {
    *error = "the folder " + output.parent_path().string() +
             " that should contain the output does not exist";
    return false;
  }
  return true;
}

// Moves the written `temporary` folder to `output`; on failure removes it
// and restores the old output.
bool ReplaceOutputFolder(const fs::path& temporary, const fs::path& output,
                         const std::string& output_path, bool output_exists,
                         std::string* error) {
  std::error_code code;
  // An empty folder in the way is replaced by the rename itself (POSIX); a
  // non-empty one (with overwrite) is first moved aside and removed once the
  // new folder is in place, or moved back if that fails.
  fs::path old_output;
  if (output_exists && !fs::is_empty(output, code)) {
    old_output = TemporarySibling(output, "old");
    fs::rename(output, old_output, code);
    if (code) {
      *error = "cannot move the old output folder " + output_path +
               " aside: " + code.message();
      RemoveFolder(temporary);
      return false;
    }
  }
  fs::rename(temporary, output, code);
  if (code) {
    *error = "cannot rename " + temporary.string() + " to " + output_path +
             ": " + code.message();
    RemoveFolder(temporary);
    if (!old_output.empty()) {
      std::error_code ignored;
      fs::rename(old_output, output, ignored);
    }
    return false;
  }
  if (!old_output.empty()) RemoveFolder(old_output);
  return true;
}

}  // namespace

bool WriteFolderAtomically(
    const std::string& output_path, const OutputFolderOptions& options,
    const std::function<bool(const std::string& folder, std::string* error)>&
        write_contents,
    std::string* error) {
  if (output_path.empty()) {
    *error = "the output path is empty";
    return false;
  }
  fs::path output;
  bool output_exists = false;
  if (!CheckOutputFolder(output_path, options, &output, &output_exists,
                         error)) {
    return false;
  }
  std::error_code code;
  const fs::path temporary = TemporarySibling(output, "tmp");
  if (!fs::create_directory(temporary, code) || code) {
    *error = "cannot create the folder " + temporary.string() + ": " +
             code.message();
    return false;
  }
  bool written = false;
  try {
    written = write_contents(temporary.string(), error);
  } catch (...) {
    RemoveFolder(temporary);
    throw;
  }
  if (!written) {
    RemoveFolder(temporary);
    return false;
  }
  return ReplaceOutputFolder(temporary, output, output_path, output_exists,
                             error);
}

}  // namespace rig_calibrator
