// Arithmetic on sizes read from files, which an attacker chooses: every count × stride × size is
// computed here, so a wrapped product can never pass a bounds check.
#pragma once

#include <cstdint>
#include <optional>

namespace hairgen {

// a × b, or nullopt when it does not fit in 64 bits.
inline std::optional<uint64_t> checkedMul(uint64_t a, uint64_t b) {
  uint64_t r;
  if (__builtin_mul_overflow(a, b, &r)) return std::nullopt;
  return r;
}

// a + b, or nullopt when it does not fit in 64 bits.
inline std::optional<uint64_t> checkedAdd(uint64_t a, uint64_t b) {
  uint64_t r;
  if (__builtin_add_overflow(a, b, &r)) return std::nullopt;
  return r;
}

// Whether `count` elements of `elementSize` bytes, `stride` bytes apart, starting `offset` bytes in,
// lie within `available` bytes: offset + stride·(count − 1) + elementSize <= available, in exact
// arithmetic. Zero elements always fit.
inline bool extentFits(uint64_t offset, uint64_t count, uint64_t stride, uint64_t elementSize,
                       uint64_t available) {
  if (count == 0) return true;
  std::optional<uint64_t> span = checkedMul(stride, count - 1);
  if (!span) return false;
  std::optional<uint64_t> end = checkedAdd(*span, elementSize);
  if (!end) return false;
  end = checkedAdd(*end, offset);
  return end && *end <= available;
}

}  // namespace hairgen
