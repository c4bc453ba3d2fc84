#pragma once
// splitmix64 (Steele, Lea and Flood): a counter-based 64-bit hash for
// deterministic per-item randomness, the same on every platform.

#include <cstdint>

namespace nadir::core {

inline std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// A uniform number in (0, 1) from a hash: its top 53 bits, centred in their cell.
inline double uniformOpen01(std::uint64_t h) {
  return (static_cast<double>(h >> 11) + 0.5) / 9007199254740992.0;
}

}  // namespace nadir::core
