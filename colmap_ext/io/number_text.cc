#include "colmap_ext/io/number_text.h"

#include <charconv>
#include <cmath>
#include <system_error>

namespace rig_calibrator {

std::string FormatDouble(double value) {
  char buffer[64];
  const std::to_chars_result result =
      std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

void AppendDouble(double value, std::string* text) {
  char buffer[64];
  const std::to_chars_result result =
      std::to_chars(buffer, buffer + sizeof(buffer), value);
  text->append(buffer, result.ptr);
}

void AppendInt64(int64_t value, std::string* text) {
  char buffer[24];
  const std::to_chars_result result =
      std::to_chars(buffer, buffer + sizeof(buffer), value);
  text->append(buffer, result.ptr);
}

std::string FormatYamlFloat(double value) {
  std::string text = FormatDouble(value);
  if (!std::isfinite(value)) {
    return text;
  }
  const size_t exponent = text.find('e');
  const std::string mantissa = text.substr(0, exponent);
  if (mantissa.find('.') == std::string::npos) {
    text.insert(exponent == std::string::npos ? text.size() : exponent, ".0");
  }
  return text;
}

namespace {

// std::from_chars of the whole text; it rejects a leading '+', which some
// writers emit, so that is dropped first (but not "+-").
template <typename Number>
bool ParseWholeNumber(std::string_view text, Number* value) {
  if (!text.empty() && text.front() == '+') {
    text.remove_prefix(1);
    if (!text.empty() && text.front() == '-') {
      return false;
    }
  }
  if (text.empty()) {
    return false;
  }
  Number parsed = 0;
  const std::from_chars_result result =
      std::from_chars(text.data(), text.data() + text.size(), parsed);
  if (result.ec != std::errc() || result.ptr != text.data() + text.size()) {
    return false;
  }
  *value = parsed;
  return true;
}

}  // namespace

bool ParseDouble(std::string_view text, double* value) {
  double parsed = 0;
  if (!ParseWholeNumber(text, &parsed) || !std::isfinite(parsed)) {
    return false;
  }
  *value = parsed;
  return true;
}

bool ParseInt64(std::string_view text, int64_t* value) {
  return ParseWholeNumber(text, value);
}

}  // namespace rig_calibrator
