// Sixteen lanes of floats for the step of Anjyo's dynamics, which takes sixteen strands at once
// (anjyo_kernel.inc). Written with GCC's vector extensions, so one source builds for any x86-64 (each vector
// split into the registers the target has) and for AVX-512 (one register a vector); every operation is one
// IEEE operation per lane, so both builds give the same bits. The files using them are built without
// contraction into fused multiply-adds.
//
// The few operations GCC builds poorly from the generic form (comparisons, which it split into one
// scalar compare per lane in large functions, and square roots) are an instruction set's own: `Isa` is
// PortableIsa or Avx512Isa, and the kernel calls them through it.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include <immintrin.h>

namespace hairgen::lanes16 {

constexpr size_t kWidth = 16;

using F = float __attribute__((vector_size(kWidth * sizeof(float))));
using I = int32_t __attribute__((vector_size(kWidth * sizeof(int32_t))));  // a mask: all ones or zero

struct F3 {
  F x, y, z;
};

// Every helper is forced inline, so it takes the instruction set of the function it is built into.
#define HAIRGEN_LANES16 [[gnu::always_inline]] inline

HAIRGEN_LANES16 F splat(float v) {
  return F{} + v;
}
HAIRGEN_LANES16 F3 splat3(float x, float y, float z) {
  return {splat(x), splat(y), splat(z)};
}
HAIRGEN_LANES16 F load(const float* v) {
  F r;
  __builtin_memcpy(&r, v, sizeof(F));
  return r;
}
HAIRGEN_LANES16 void store(float* to, F v) {
  __builtin_memcpy(to, &v, sizeof(F));
}
HAIRGEN_LANES16 F3 load3(const float (&v)[3][kWidth]) {
  return {load(v[0]), load(v[1]), load(v[2])};
}
HAIRGEN_LANES16 void store3(float (&to)[3][kWidth], const F3& v) {
  store(to[0], v.x);
  store(to[1], v.y);
  store(to[2], v.z);
}

HAIRGEN_LANES16 F3 operator+(const F3& a, const F3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
HAIRGEN_LANES16 F3 operator-(const F3& a, const F3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
HAIRGEN_LANES16 F3 operator-(const F3& a) {
  return {-a.x, -a.y, -a.z};
}
HAIRGEN_LANES16 F3 operator*(F s, const F3& a) {
  return {s * a.x, s * a.y, s * a.z};
}
HAIRGEN_LANES16 F dot(const F3& a, const F3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
HAIRGEN_LANES16 F3 cross(const F3& a, const F3& b) {
  return {a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y};
}
HAIRGEN_LANES16 F select(I m, F a, F b) {
  return m ? a : b;
}
HAIRGEN_LANES16 I select(I m, I a, I b) {
  return m ? a : b;
}
HAIRGEN_LANES16 F3 select(I m, const F3& a, const F3& b) {
  return {m ? a.x : b.x, m ? a.y : b.y, m ? a.z : b.z};
}
HAIRGEN_LANES16 F abs(F v) {
  return __builtin_bit_cast(F, __builtin_bit_cast(I, v) & 0x7fffffff);
}
HAIRGEN_LANES16 F copySign(F magnitude, F sign) {
  return __builtin_bit_cast(F, (__builtin_bit_cast(I, magnitude) & 0x7fffffff) |
                                   (__builtin_bit_cast(I, sign) & int32_t(0x80000000)));
}

// Any x86-64: comparisons and square roots as the generic vectors build them; a comparison's result is a
// vector of masks (I).
struct PortableIsa {
  using Mask = I;
  HAIRGEN_LANES16 static F select(Mask m, F a, F b) { return lanes16::select(m, a, b); }
  HAIRGEN_LANES16 static F3 select(Mask m, const F3& a, const F3& b) { return lanes16::select(m, a, b); }
  HAIRGEN_LANES16 static Mask select(Mask m, Mask a, Mask b) { return lanes16::select(m, a, b); }
  HAIRGEN_LANES16 static I less(F a, F b) { return a < b; }
  HAIRGEN_LANES16 static I lessEqual(F a, F b) { return a <= b; }
  HAIRGEN_LANES16 static F sqrt(F v) {
    for (size_t l = 0; l < kWidth; ++l) v[l] = __builtin_sqrtf(v[l]);
    return v;
  }
  HAIRGEN_LANES16 static bool any(I m) {
    int32_t r = 0;
    for (size_t l = 0; l < kWidth; ++l) r |= m[l];
    return r != 0;
  }
  // Column l of a tile of `rows` rows of kWidth floats (row r at tile + r·kWidth), its first valid[l]
  // floats, written to to[l], for every lane with valid[l] > 0: lanes of strands to the strands' arrays.
  HAIRGEN_LANES16 static void storeColumns(const float* tile, int rows, float* const (&to)[kWidth],
                                           const int (&valid)[kWidth]) {
    for (size_t l = 0; l < kWidth; ++l)
      for (int r = 0; r < std::min(rows, valid[l]); ++r) to[l][r] = tile[size_t(r) * kWidth + l];
  }
};

// AVX-512 F and DQ: one instruction each. (Callers are built for that instruction set.)
#define HAIRGEN_AVX512 [[gnu::always_inline, gnu::target("avx512f,avx512dq")]] inline
// AVX-512's comparison result: a bit a lane, kept in a mask register (as a vector of masks it took a
// vector register and a conversion each way, and the step spilled vectors for it).
struct Mask16 {
  __mmask16 k;
  HAIRGEN_LANES16 bool operator[](size_t l) const { return (k >> l) & 1u; }
  HAIRGEN_LANES16 friend Mask16 operator&(Mask16 a, Mask16 b) { return {__mmask16(a.k & b.k)}; }
  HAIRGEN_LANES16 friend Mask16 operator|(Mask16 a, Mask16 b) { return {__mmask16(a.k | b.k)}; }
  HAIRGEN_LANES16 friend Mask16 operator~(Mask16 a) { return {__mmask16(~a.k)}; }
  HAIRGEN_LANES16 Mask16& operator|=(Mask16 b) { return *this = *this | b; }
};
struct Avx512Isa {
  using Mask = Mask16;
  template <int kPredicate>
  HAIRGEN_AVX512 static Mask compare(F a, F b) {
    return {_mm512_cmp_ps_mask(__m512(a), __m512(b), kPredicate)};
  }
  HAIRGEN_AVX512 static Mask less(F a, F b) { return compare<_CMP_LT_OQ>(a, b); }
  HAIRGEN_AVX512 static Mask lessEqual(F a, F b) { return compare<_CMP_LE_OQ>(a, b); }
  HAIRGEN_AVX512 static F sqrt(F v) { return F(_mm512_mask_sqrt_ps(__m512(v), 0xffff, __m512(v))); }
  HAIRGEN_AVX512 static bool any(Mask m) { return m.k != 0; }
  HAIRGEN_AVX512 static F select(Mask m, F a, F b) {
    return F(_mm512_mask_blend_ps(m.k, __m512(b), __m512(a)));
  }
  HAIRGEN_AVX512 static F3 select(Mask m, const F3& a, const F3& b) {
    return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
  }
  HAIRGEN_AVX512 static Mask select(Mask m, Mask a, Mask b) { return (m & a) | (~m & b); }
  // PortableIsa::storeColumns, 16 rows at a time transposed in registers and stored a column at once.
  HAIRGEN_AVX512 static void storeColumns(const float* tile, int rows, float* const (&to)[kWidth],
                                          const int (&valid)[kWidth]) {
    for (int first = 0; first < rows; first += int(kWidth)) {
      __m512 r[kWidth];
      for (size_t i = 0; i < kWidth; ++i)
        r[i] = first + int(i) < rows ? _mm512_loadu_ps(tile + (size_t(first) + i) * kWidth)
                                     : _mm512_setzero_ps();
      transpose(r);
      // Whole columns by plain stores: a masked store to memory costs several times as much on some
      // processors (AMD Zen 4), and most columns are whole.
      for (size_t l = 0; l < kWidth; ++l) {
        const int count = std::min(rows, valid[l]) - first;
        if (count >= int(kWidth))
          _mm512_storeu_ps(to[l] + first, r[l]);
        else if (count > 0)
          _mm512_mask_storeu_ps(to[l] + first, __mmask16((1u << count) - 1), r[l]);
      }
    }
  }
  // r[i][l] becomes r[l][i]: 4×4 blocks within each 128-bit quarter, then the quarters.
  HAIRGEN_AVX512 static void transpose(__m512 (&r)[kWidth]) {
    __m512 t[kWidth];
    for (size_t i = 0; i < kWidth; i += 2) {
      t[i] = _mm512_mask_unpacklo_ps(r[i], 0xffff, r[i], r[i + 1]);
      t[i + 1] = _mm512_mask_unpackhi_ps(r[i], 0xffff, r[i], r[i + 1]);
    }
    for (size_t i = 0; i < kWidth; i += 4) {
      r[i] = _mm512_castpd_ps(_mm512_mask_unpacklo_pd(_mm512_castps_pd(t[i]), 0xff, _mm512_castps_pd(t[i]),
                                                      _mm512_castps_pd(t[i + 2])));
      r[i + 1] = _mm512_castpd_ps(_mm512_mask_unpackhi_pd(
          _mm512_castps_pd(t[i]), 0xff, _mm512_castps_pd(t[i]), _mm512_castps_pd(t[i + 2])));
      r[i + 2] = _mm512_castpd_ps(_mm512_mask_unpacklo_pd(
          _mm512_castps_pd(t[i + 1]), 0xff, _mm512_castps_pd(t[i + 1]), _mm512_castps_pd(t[i + 3])));
      r[i + 3] = _mm512_castpd_ps(_mm512_mask_unpackhi_pd(
          _mm512_castps_pd(t[i + 1]), 0xff, _mm512_castps_pd(t[i + 1]), _mm512_castps_pd(t[i + 3])));
    }
    // Now quarter q of r[4a + b] holds rows 4q … 4q + 3 of column 4a + b's … : gather the quarters.
    for (size_t i = 0; i < 4; ++i) {
      t[i] = _mm512_mask_shuffle_f32x4(r[i], 0xffff, r[i], r[i + 4], 0x88);
      t[i + 4] = _mm512_mask_shuffle_f32x4(r[i], 0xffff, r[i], r[i + 4], 0xdd);
      t[i + 8] = _mm512_mask_shuffle_f32x4(r[i + 8], 0xffff, r[i + 8], r[i + 12], 0x88);
      t[i + 12] = _mm512_mask_shuffle_f32x4(r[i + 8], 0xffff, r[i + 8], r[i + 12], 0xdd);
    }
    for (size_t i = 0; i < 4; ++i) {
      r[i] = _mm512_mask_shuffle_f32x4(t[i], 0xffff, t[i], t[i + 8], 0x88);
      r[i + 8] = _mm512_mask_shuffle_f32x4(t[i], 0xffff, t[i], t[i + 8], 0xdd);
      r[i + 4] = _mm512_mask_shuffle_f32x4(t[i + 4], 0xffff, t[i + 4], t[i + 12], 0x88);
      r[i + 12] = _mm512_mask_shuffle_f32x4(t[i + 4], 0xffff, t[i + 4], t[i + 12], 0xdd);
    }
  }
};

}  // namespace hairgen::lanes16
