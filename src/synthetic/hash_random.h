// Counter-based random numbers for the procedural scene and the renderer:
// values are pure functions of (seed, position), so they do not depend on the
// order of evaluation or on thread scheduling.
#pragma once

#include <cstdint>

namespace rig_calibrator {

// splitmix64's finalizer: a bijective 64-bit mix with full avalanche, so
// hashes of neighbouring inputs are unrelated.
inline uint64_t Mix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// Uniform in [0, 1) from the top 53 bits of a hash.
inline double ToUnit(uint64_t hash) {
  return static_cast<double>(hash >> 11) * 0x1.0p-53;
}

}  // namespace rig_calibrator
