// FNV-1a, 64 bit (Fowler, Noll and Vo; IETF draft-eastlake-fnv): the digests that tell hairgen's inputs
// apart (Config::digest, restGuidesDigest). An identity for equal inputs, not a cryptographic hash.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>

namespace hairgen {

inline constexpr uint64_t kFnvOffsetBasis = 0xcbf29ce484222325ull;  // FNV-1a 64's digest of no bytes
inline constexpr uint64_t kFnvPrime = 0x100000001b3ull;             // 2^40 + 2^8 + 0xb3

// FNV-1a over `bytes` bytes at `data`, continuing from `hash` (kFnvOffsetBasis starts a digest). No
// default for `hash`: fnv1a("text", hash) must not read as (data, bytes).
inline uint64_t fnv1a(const void* data, size_t bytes, uint64_t hash) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < bytes; ++i) hash = (hash ^ p[i]) * kFnvPrime;
  return hash;
}
inline uint64_t fnv1a(std::string_view text, uint64_t hash = kFnvOffsetBasis) {
  return fnv1a(text.data(), text.size(), hash);
}

// FNV-1a's step over 64-bit words (in the machine's byte order) in four independent lanes seeded from
// `hash`, the lanes folded together, then fnv1a over the last bytes that fill no 32: a coupe's megabytes
// of rest points hash at memory speed rather than one dependent multiply a byte. Its value is its own,
// not FNV-1a's of the same bytes.
inline uint64_t fnv1aLanes(const void* data, size_t bytes, uint64_t hash) {
  const auto* p = static_cast<const unsigned char*>(data);
  uint64_t lanes[4] = {hash, hash ^ 1, hash ^ 2, hash ^ 3};
  size_t i = 0;
  for (; i + sizeof lanes <= bytes; i += sizeof lanes)
    for (size_t l = 0; l < 4; ++l) {
      uint64_t word;
      std::memcpy(&word, p + i + l * sizeof word, sizeof word);
      lanes[l] = (lanes[l] ^ word) * kFnvPrime;
    }
  hash = lanes[0];
  for (size_t l = 1; l < 4; ++l) hash = (hash ^ lanes[l]) * kFnvPrime;
  return fnv1a(p + i, bytes - i, hash);
}

}  // namespace hairgen
