#include "colmap_ext/commands/colmap_help.h"

#include <algorithm>
#include <sstream>
#include <vector>

namespace rig_calibrator {
namespace {

constexpr char kCommand[] = "rig_calibrator";
constexpr char kIndent[] = "  ";

std::vector<std::string> SplitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream stream(text);
  for (std::string line; std::getline(stream, line);) lines.push_back(line);
  return lines;
}

bool IsCommandLine(const std::string& line) {
  return line.size() > 2 && line.compare(0, 2, kIndent) == 0 && line[2] != ' ';
}

}  // namespace

std::string ExtendColmapHelp(const std::string& colmap_help) {
  const std::string command_line = std::string(kIndent) + kCommand + "\n";
  const std::string paragraph =
      "Added by rig_calibrator (multi-camera rig calibration; the commands "
      "above\nare COLMAP 3.8's own):\n"
      "  colmap rig_calibrator help\n"
      "  colmap rig_calibrator --database_path DATABASE --image_path IMAGES "
      "\\\n"
      "      --input_path MODEL --output_path OUTPUT\n\n";
  const std::vector<std::string> lines = SplitLines(colmap_help);
  size_t list = 0;
  while (list < lines.size() && lines[list] != "Available commands:") ++list;
  if (list == lines.size())
    return colmap_help + command_line + "\n" + paragraph;

  // The list's first entry is "help"; the others are sorted.
  size_t end = list + 1;
  while (end < lines.size() && IsCommandLine(lines[end])) ++end;
  size_t insert = std::min(list + 2, end);
  while (insert < end && lines[insert].substr(2) < kCommand) ++insert;
  // The paragraph follows the blank line that closes the list.
  const size_t after = end < lines.size() && lines[end].empty() ? end + 1 : end;

  std::string text;
  for (size_t k = 0; k <= lines.size(); ++k) {
    if (k == insert) text += command_line;
    if (k == after) text += paragraph;
    if (k < lines.size()) text += lines[k] + "\n";
  }
  return text;
}

}  // namespace rig_calibrator
