#include "colmap_ext/io/atomic_output.h"

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
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

// The process id in the name of a temporary sibling of `path` with one of
// `tags` (".NAME.TAG-PID-RANDOM", TemporarySibling), or 0 for other names.
pid_t TemporarySiblingOwner(const fs::path& path, const std::string& name,
                            const std::vector<std::string>& tags) {
  for (const std::string& tag : tags) {
    const std::string prefix = "." + path.filename().string() + "." + tag + "-";
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = name.substr(prefix.size());
    const size_t dash = rest.find('-');
    if (dash == 0 || dash == std::string::npos ||
        rest.find_first_not_of("0123456789") != dash ||
        rest.find_first_not_of("0123456789", dash + 1) != std::string::npos) {
      return 0;
    }
    return static_cast<pid_t>(std::stoll(rest.substr(0, dash)));
  }
  return 0;
}

// Removes the temporary siblings (files or folders) of `path` that a killed
// run left behind (kill -9, power loss): those whose process no longer
// exists. Running
// processes' folders (e.g. a run into the same output right now) are kept.
void RemoveStaleSiblings(const fs::path& path) {
  const fs::path parent =
      path.parent_path().empty() ? fs::path(".") : path.parent_path();
  std::error_code code;
  std::vector<fs::path> stale;
  for (fs::directory_iterator it(parent, code), end; !code && it != end;
       it.increment(code)) {
    const pid_t owner = TemporarySiblingOwner(
        path, it->path().filename().string(), {"tmp", "old"});
    if (owner > 0 && owner != getpid() && kill(owner, 0) != 0 &&
        errno == ESRCH) {
      stale.push_back(it->path());
    }
  }
  for (const fs::path& folder : stale) {
    std::error_code ignored;
    fs::remove_all(folder, ignored);
    std::cout << "Removed " << folder.string()
              << ", left by an interrupted run (its process no longer exists)"
              << std::endl;
  }
}

// rename(2) with flags (RENAME_NOREPLACE, RENAME_EXCHANGE): 0 or an errno.
int RenameWithFlags(const fs::path& from, const fs::path& to,
                    unsigned int flags) {
  if (renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), flags) == 0) {
    return 0;
  }
  return errno;
}

}  // namespace

bool WriteFileAtomically(const std::string& path, const std::string& contents,
                         std::string* error) {
  return WriteFileAtomically(path, std::vector<std::string_view>{contents},
                             error);
}

bool WriteFileAtomically(const std::string& path,
                         const std::vector<std::string_view>& pieces,
                         std::string* error) {
  RemoveStaleSiblings(path);
  const fs::path temporary = TemporarySibling(path, "tmp");
  {
    std::ofstream file(temporary, std::ios::binary | std::ios::trunc);
    if (!file) {
      *error = "cannot create " + temporary.string();
      return false;
    }
    for (const std::string_view piece : pieces) {
      file.write(piece.data(), static_cast<std::streamsize>(piece.size()));
    }
    file.close();
    if (!file) {
      // errno of the failed write or close, e.g. ENOSPC on a full disk.
      const int write_errno = errno;
      const std::string reason =
          std::strerror(write_errno) +
          std::string(write_errno == ENOSPC
                          ? " (free space there or choose another output "
                            "folder)"
                          : "");
      std::error_code ignored;
      fs::remove(temporary, ignored);
      *error = "cannot write " + temporary.string() + " (for " + path +
               "): " + reason;
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
                       std::string* error) {
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
  if (fs::exists(output, code)) {
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

// The message when another process filled the output folder while this
// run wrote its temporary folder.
std::string ConcurrentRunError(const std::string& output_path) {
  return "the output folder " + output_path +
         " was created or filled by another process while this run was "
         "writing (two runs into the same output?); this run's output is "
         "discarded and that folder is left as it is: choose another output "
         "folder";
}

// Moves the written `temporary` folder to `output` in one step, so the output
// is never partial, and never mixes two runs':
//  - no output folder: rename with RENAME_NOREPLACE, which fails if another
//    run created it meanwhile;
//  - an empty one: removed (rmdir fails if another run filled it), then as
//    above;
//  - a non-empty one (overwrite): RENAME_EXCHANGE swaps old and new
//    atomically, and the old one, now at the temporary name, is removed (a
//    run killed before that leaves it to RemoveStaleSiblings).
// File systems without these flags (EINVAL) get plain renames: the old output
// moved aside, then the new one moved in.
bool ReplaceOutputFolder(const fs::path& temporary, const fs::path& output,
                         const std::string& output_path, bool allow_overwrite,
                         std::string* error) {
  std::error_code code;
  const bool exists = fs::exists(output, code);
  // Without overwrite, a folder filled since CheckOutputFolder is another
  // run's: rmdir below refuses to remove it.
  const bool overwrite =
      allow_overwrite && exists && !fs::is_empty(output, code);
  int result = 0;
  if (overwrite) {
    result = RenameWithFlags(temporary, output, RENAME_EXCHANGE);
    if (result == EINVAL) {
      const fs::path old_output = TemporarySibling(output, "old");
      result = RenameWithFlags(output, old_output, 0);
      if (result == 0) {
        result = RenameWithFlags(temporary, output, 0);
        if (result != 0) {
          RenameWithFlags(old_output, output, 0);
        } else {
          fs::rename(old_output, temporary, code);
        }
      }
    }
  } else {
    if (exists && rmdir(output.c_str()) != 0 && errno != ENOENT) {
      *error = errno == ENOTEMPTY || errno == EEXIST
                   ? ConcurrentRunError(output_path)
                   : "cannot replace the empty output folder " + output_path +
                         ": " + std::strerror(errno);
      RemoveFolder(temporary);
      return false;
    }
    result = RenameWithFlags(temporary, output, RENAME_NOREPLACE);
    if (result == EINVAL) {
      result = fs::exists(output, code) ? EEXIST
                                        : RenameWithFlags(temporary, output, 0);
    }
    if (result == EEXIST || result == ENOTEMPTY) {
      *error = ConcurrentRunError(output_path);
      RemoveFolder(temporary);
      return false;
    }
  }
  if (result != 0) {
    *error = "cannot rename " + temporary.string() + " to " + output_path +
             ": " + std::strerror(result);
    RemoveFolder(temporary);
    return false;
  }
  // After an exchange the temporary name holds the old output.
  RemoveFolder(temporary);
  return true;
}

}  // namespace

bool CheckOutputFolderUsable(const std::string& output_path,
                             const OutputFolderOptions& options,
                             std::string* error) {
  if (output_path.empty()) {
    *error = "the output path is empty";
    return false;
  }
  fs::path output;
  if (!CheckOutputFolder(output_path, options, &output, error)) return false;
  // access() reports a read-only file system (EROFS) even to root, who
  // passes every permission check.
  const fs::path parent =
      output.parent_path().empty() ? fs::path(".") : output.parent_path();
  if (access(parent.c_str(), W_OK) != 0) {
    *error = "cannot write into " + parent.string() +
             ", the folder that should hold the output folder " + output_path +
             ": " + std::strerror(errno) +
             "; choose an --output_path on a writable file system";
    return false;
  }
  return true;
}

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
  if (!CheckOutputFolder(output_path, options, &output, error)) {
    return false;
  }
  RemoveStaleSiblings(output);
  std::error_code code;
  const fs::path temporary = TemporarySibling(output, "tmp");
  if (!fs::create_directory(temporary, code) || code) {
    *error = "cannot create the temporary folder " + temporary.string() +
             " next to the output folder " + output_path + ": " +
             code.message() +
             "; the folder that holds the output must be writable (choose "
             "another --output_path)";
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
  return ReplaceOutputFolder(temporary, output, output_path, options.overwrite,
                             error);
}

}  // namespace rig_calibrator
