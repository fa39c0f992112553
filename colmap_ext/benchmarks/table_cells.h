// Cells of the benchmarks' Markdown tables.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

namespace rig_calibrator {

// `value` with `digits` decimals; "-" when it is not finite.
inline std::string FixedCell(double value, int digits) {
  if (!std::isfinite(value)) return "-";
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", digits, value);
  return text;
}

// numerator / denominator with two decimals; "-" when the denominator is not
// positive or the numerator not finite.
inline std::string RatioCell(double numerator, double denominator) {
  return denominator > 0 && std::isfinite(numerator)
             ? FixedCell(numerator / denominator, 2)
             : "-";
}

}  // namespace rig_calibrator
