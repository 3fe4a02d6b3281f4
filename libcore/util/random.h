// Counter-based random numbers (DESIGN §2): every value is a pure function of its key, so a strand's
// numbers depend only on (seed, triangle, strand) and never on thread count or evaluation order.
#pragma once

#include <cstdint>

namespace hairgen {

// SplitMix64's finaliser: a bijection on 64 bits with full avalanche.
constexpr uint64_t mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// 64 random bits keyed by (seed, a, b, stream); each word passes through the mixer in turn, so keys
// that differ in any word give unrelated values.
constexpr uint64_t counterBits(uint64_t seed, uint64_t a, uint64_t b, uint64_t stream) {
  return mix64(mix64(mix64(mix64(seed) ^ a) ^ b) ^ stream);
}

// A uniform double in [0, 1) with 53 random bits.
constexpr double counterUniform(uint64_t seed, uint64_t a, uint64_t b, uint64_t stream) {
  return static_cast<double>(counterBits(seed, a, b, stream) >> 11) * 0x1.0p-53;
}

}  // namespace hairgen
