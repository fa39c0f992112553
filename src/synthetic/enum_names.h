// The names of an enumeration, from one table per enumeration: parsing,
// printing and listing all values (the command-line names of the rig presets
// and scene types).
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

namespace rig_calibrator {

template <typename Enum, size_t N>
using EnumNameTable = std::array<std::pair<Enum, const char*>, N>;

// The name of `value` in the table, "unknown" if it has none.
template <typename Enum, size_t N>
std::string EnumName(const EnumNameTable<Enum, N>& table, Enum value) {
  for (const auto& [candidate, name] : table) {
    if (candidate == value) return name;
  }
  return "unknown";
}

// Sets *value to the entry named `name`; false (and *value unchanged) if no
// entry has that name.
template <typename Enum, size_t N>
bool EnumFromName(const EnumNameTable<Enum, N>& table, const std::string& name,
                  Enum* value) {
  for (const auto& [candidate, candidate_name] : table) {
    if (name == candidate_name) {
      *value = candidate;
      return true;
    }
  }
  return false;
}

// All values, in the order of the table.
template <typename Enum, size_t N>
std::vector<Enum> EnumValues(const EnumNameTable<Enum, N>& table) {
  std::vector<Enum> values;
  for (const auto& entry : table) values.push_back(entry.first);
  return values;
}

}  // namespace rig_calibrator
