// Counter-based random numbers: value i of stream s is a pure function of
// (seed, stream, i), so ray sets and procedural scenes come out bit-identical
// on every machine, whatever the thread count. std:: distributions are not
// used because their output is implementation-defined.
#pragma once

#include <cstdint>

namespace raybench {

// SplitMix64 finaliser (Steele, Lea & Flood, OOPSLA 2014).
constexpr std::uint64_t mix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

class Rng {
 public:
  constexpr Rng(std::uint64_t seed, std::uint64_t stream, std::uint64_t index)
      : state_(mix64(mix64(seed ^ mix64(stream)) ^ index)) {}

  constexpr std::uint64_t next_u64() { return mix64(state_++); }
  // Uniform in [0, 1) with 53 random bits.
  constexpr double next_double() { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }

 private:
  std::uint64_t state_;
};

// Stable 64-bit hash of a string, to derive streams from names.
constexpr std::uint64_t hash_string(const char* s) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (; *s; ++s) h = (h ^ static_cast<unsigned char>(*s)) * 0x100000001b3ull;
  return h;
}

}  // namespace raybench
