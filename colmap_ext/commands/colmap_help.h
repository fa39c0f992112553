// The help of the extended colmap executable (colmap_main.cc): COLMAP's own
// `colmap help` text with the rig_calibrator command added.
#pragma once

#include <string>

namespace rig_calibrator {

// `colmap_help` (what COLMAP 3.8's `colmap help` prints) with
// "  rig_calibrator" inserted in alphabetical order into the list under
// "Available commands:" (after "help", which COLMAP lists first) and, after
// the list, a paragraph saying how to run it. Every line of COLMAP's text is
// kept, in its order; a text without the list gets the line and the paragraph
// at its end.
std::string ExtendColmapHelp(const std::string& colmap_help);

}  // namespace rig_calibrator
