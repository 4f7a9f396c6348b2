// splitmix64: a portable generator for the mesher's deterministic randomness (std
// distributions differ between standard libraries, and meshes must be the same everywhere).
#pragma once

#include <cstdint>

namespace hexfem {

struct SplitMix {
  std::uint64_t s;
  // The next number in [0, 1).
  double uniform() {
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) * 0x1.0p-53;
  }
};

// The i-th number of the stream started at 0: a number in [0, 1) that depends only on i.
inline double splitmix_at(std::uint64_t i) {
  return SplitMix{0x9E3779B97F4A7C15ull * i}.uniform();
}

}  // namespace hexfem
