// Numbers in the project's text formats: written so that reading them back
// gives the same double bit for bit, and read strictly (the whole token must be
// a number, nothing else).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace rig_calibrator {

// The shortest decimal text that reads back as exactly `value`
// (std::to_chars), e.g. "312.41", "1e-05", "-0.5".
std::string FormatDouble(double value);
// FormatDouble(value) appended to *text, without a string of its own (a
// correspondence file has 10^7 numbers).
void AppendDouble(double value, std::string* text);
// The decimal text of `value` appended to *text.
void AppendInt64(int64_t value, std::string* text);

// As FormatDouble, but always with a decimal point in the mantissa
// ("500.0", "1.0e-05"): YAML 1.1 readers such as PyYAML (used by Kalibr) read
// "500" as an integer and "1e-05" as a string.
std::string FormatYamlFloat(double value);

// True if `text` is entirely one finite number.
bool ParseDouble(std::string_view text, double* value);
// True if `text` is entirely one integer in the range of int64_t.
bool ParseInt64(std::string_view text, int64_t* value);

}  // namespace rig_calibrator
