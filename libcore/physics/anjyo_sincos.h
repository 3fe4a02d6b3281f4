// sin and cos for Anjyo's step, by arithmetic alone, so that the strand-by-strand step and the vector
// one (anjyo_lanes.cpp) agree bit for bit: `T` is double or a vector of doubles, and every operation is
// one IEEE operation per lane (no library call, whose result could differ between its scalar and vector
// versions). Accurate to about an ulp.
#pragma once

#include <bit>
#include <cstdint>
#include <type_traits>

namespace hairgen {

// sin x and cos x for any finite x of moderate size (|x| < 10⁵: the reduction below is exact there).
// x is reduced by the nearest multiple k of π/2 (Cody and Waite, π/2 in three parts of which the first
// two times k are exact), then sin and cos of the rest r, |r| ≤ π/4, by polynomials of degree 13 and 14
// with Remez minimax coefficients (the published figures of Sun's fdlibm; measured against the library
// on a grid of 200,001 points, within 2.3e-16 relative and 1.2e-16 absolute), then the quadrant k mod 4
// picks and signs them.
template <class T>
[[gnu::always_inline]] inline void sinCos(T x, T& s, T& c) {
  constexpr double kTwoOverPi = 0.636619772367581343076;
  constexpr double kPiOver2[3] = {1.57079632673412561417e+00, 6.07710050630396597660e-11,
                                  2.02226624871116645580e-21};
  constexpr double kRound = 6755399441055744.0;  // 1.5·2⁵²: adding and taking it away rounds to an integer
  constexpr double s1 = -1.66666666666666324348e-01, s2 = 8.33333333332248946124e-03,
                   s3 = -1.98412698298579493134e-04, s4 = 2.75573137070700676789e-06,
                   s5 = -2.50507602534068634195e-08, s6 = 1.58969099521155010221e-10;
  constexpr double c1 = 4.16666666666666019037e-02, c2 = -1.38888888888741095749e-03,
                   c3 = 2.48015872894767294178e-05, c4 = -2.75573143513906633035e-07,
                   c5 = 2.08757232129817482790e-09, c6 = -1.13596475577881948265e-11;
  const T k = (x * kTwoOverPi + kRound) - kRound;
  const T r = ((x - k * kPiOver2[0]) - k * kPiOver2[1]) - k * kPiOver2[2];
  const T z = r * r;
  const T sr = r + r * z * (s1 + z * (s2 + z * (s3 + z * (s4 + z * (s5 + z * s6)))));
  const T cr = 1.0 - 0.5 * z + z * z * (c1 + z * (c2 + z * (c3 + z * (c4 + z * (c5 + z * c6)))));
  // The quadrant k mod 4 (two's complement: −1 is 3), as integers: comparisons of doubles here were
  // split into one scalar compare per lane when inlined into the vector step, a third of its time.
  // Odd quadrants swap sin and cos; quadrants 2 and 3 negate sin, 1 and 2 cos (a flip of the sign bit).
  // (k is an exact integer for finite x; a NaN, which restore() and the step's callers never pass, would
  // make the conversion undefined.)
  if constexpr (std::is_same_v<T, double>) {
    const int64_t q = int64_t(k) & 3;
    const double sinR = (q & 1) ? cr : sr, cosR = (q & 1) ? sr : cr;
    s = std::bit_cast<double>(std::bit_cast<uint64_t>(sinR) ^ (uint64_t(q & 2) << 62));
    c = std::bit_cast<double>(std::bit_cast<uint64_t>(cosR) ^ (uint64_t((q + 1) & 2) << 62));
  } else {
    using I = decltype(k < k);  // signed integers of the lanes' width
    const I q = __builtin_convertvector(k, I) & 3, odd = -(q & 1);
    const I srBits = std::bit_cast<I>(sr), crBits = std::bit_cast<I>(cr);
    const I sinR = (odd & crBits) | (~odd & srBits), cosR = (odd & srBits) | (~odd & crBits);
    s = std::bit_cast<T>(sinR ^ ((q & 2) << 62));
    c = std::bit_cast<T>(cosR ^ (((q + 1) & 2) << 62));
  }
}

}  // namespace hairgen
