// Enum values and their names in one table, read both ways: the one place
// that lists the names of a setting or file field.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace rig_calibrator {

template <typename Value>
using NameTable = std::vector<std::pair<Value, std::string>>;

// The value named `name`; false (and *value unchanged) for an unknown name.
template <typename Value>
bool ValueFromName(const NameTable<Value>& table, const std::string& name,
                   Value* value) {
  for (const auto& [entry_value, entry_name] : table) {
    if (entry_name == name) {
      *value = entry_value;
      return true;
    }
  }
  return false;
}

// The name of `value`, `unknown` if the table has none.
template <typename Value>
std::string NameOfValue(const NameTable<Value>& table, const Value& value,
                        const std::string& unknown) {
  for (const auto& [entry_value, entry_name] : table) {
    if (entry_value == value) return entry_name;
  }
  return unknown;
}

}  // namespace rig_calibrator
