// Fuzz target of the rig discovery from image names (DiscoverRigLayout: the
// camera prefixes, frameset keys and timestamp parsing) and its log table.
// Input: one option byte, then image names separated by '\n'. The option
// byte's low bits choose the timestamp tolerance (0: identical keys; 1, 1e6
// or 1e300 nanoseconds), bit 2 takes the names starting with '@' as camera
// prefixes instead of image names.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "colmap_ext/io/rig_layout.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rig_calibrator;
  if (size == 0) return 0;
  const uint8_t option = data[0];
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  constexpr double kTolerances[] = {0, 1, 1e6, 1e300};
  RigLayoutOptions options;
  options.timestamp_tolerance = kTolerances[option & 3];
  std::vector<std::string> names;
  size_t begin = 0;
  while (begin <= text.size()) {
    size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    std::string name = text.substr(begin, end - begin);
    if ((option & 4) != 0 && !name.empty() && name[0] == '@') {
      options.camera_prefixes.push_back(name.substr(1));
    } else {
      names.push_back(std::move(name));
    }
    begin = end + 1;
  }
  RigLayout layout;
  std::string error;
  if (DiscoverRigLayout(names, options, &layout, &error)) {
    if (layout.images.size() != names.size()) std::abort();
    RigLayoutTable(names, layout);
  } else if (error.empty()) {
    std::abort();
  }
  return 0;
}
