#include "colmap_ext/report/figure_format.h"

#include <cmath>
#include <cstdio>

namespace rig_calibrator {

std::string FormatSvgCoordinate(const double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f", value);
  return text;
}

double NiceBelow(const double value) {
  const double power = std::pow(10.0, std::floor(std::log10(value)));
  for (const double factor : {5.0, 2.0, 1.0}) {
    if (factor * power <= value) return factor * power;
  }
  return power;
}

}  // namespace rig_calibrator
