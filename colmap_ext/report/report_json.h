// Reading calibration_summary.json for the report: keys that other parts of
// the calibration add may be absent (the report then says "not computed"),
// and every number is shown with a fixed number of significant digits.
#pragma once

#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

namespace rig_calibrator {

using ReportJson = nlohmann::ordered_json;

// The value of `key` in `node`, or nullptr when `node` is not an object, the
// key is absent or its value is null.
inline const ReportJson* FindKey(const ReportJson& node, const char* key) {
  if (!node.is_object()) return nullptr;
  const auto it = node.find(key);
  if (it == node.end() || it->is_null()) return nullptr;
  return &*it;
}

// A number, or NaN when the value is absent or not a number.
inline double NumberOr(const ReportJson* node) {
  return node != nullptr && node->is_number()
             ? node->get<double>()
             : std::numeric_limits<double>::quiet_NaN();
}
inline double NumberAt(const ReportJson& node, const char* key) {
  return NumberOr(FindKey(node, key));
}

// A string value ("" when absent or not a string).
inline std::string TextAt(const ReportJson& node, const char* key) {
  const ReportJson* value = FindKey(node, key);
  return value != nullptr && value->is_string() ? value->get<std::string>()
                                                : std::string();
}

// `value` with `digits` significant digits ("%.*g"), "–" when not finite.
inline std::string FormatNumber(const double value, const int digits = 4) {
  if (!std::isfinite(value)) return "\u2013";
  char text[40];
  // + 0.0: -0 (e.g. the reference camera's centre) is shown as 0.
  std::snprintf(text, sizeof(text), "%.*g", digits, value + 0.0);
  return text;
}

}  // namespace rig_calibrator
