// The bytes of COLMAP's binary model files (cameras.bin, rigs.bin,
// frames.bin): plain numbers in the machine's byte order, which is little
// endian, as the formats are, on every platform COLMAP runs on.
#pragma once

#include <cstring>
#include <string>
#include <type_traits>

namespace rig_calibrator {

// Appends the sizeof(T) bytes of `value` to `bytes`.
template <typename T>
void AppendBinary(T value, std::string* bytes) {
  static_assert(std::is_arithmetic<T>::value, "plain numbers only");
  char buffer[sizeof(T)];
  std::memcpy(buffer, &value, sizeof(T));
  bytes->append(buffer, sizeof(T));
}

}  // namespace rig_calibrator
