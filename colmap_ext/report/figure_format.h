// Numbers as the report's SVG figures write them.
#pragma once

#include <string>

namespace rig_calibrator {

// A coordinate of the figure in SVG user units, one decimal ("12.3").
std::string FormatSvgCoordinate(double value);

// The largest 1, 2 or 5 times a power of ten that is at most `value` > 0: the
// length of a scale bar.
double NiceBelow(double value);

}  // namespace rig_calibrator
