// sin and cos for Anjyo's step in sixteen float lanes (float_lanes.h), by arithmetic alone: no library
// call, whose scalar and vector versions could round differently, so every build of the step gives the
// same bits.
#pragma once

#include "libcore/physics/float_lanes.h"

namespace hairgen::lanes16 {

// sin x and cos x to within about an ulp of a float (9.4e-8 of the exact values for |x| < 4, 1.2e-7 over
// ±74 rad), for |x| < 6,400 (the step keeps its angles within half a turn of 0). x is reduced by the
// nearest multiple k of π/2 (Cody and Waite: π/2 in three parts, the first of 8 significant bits and the
// second of 12, so that k times each is exact for |k| < 4,096), and sin and cos of the rest r
// (|r| ≤ π/4) are polynomials of degree 7 and 8 in r whose coefficients were fitted for this file
// (minimax, by Lawson's iteration: 3.8e-9 relative for sin, 9.5e-11 absolute for cos). The quadrant
// k mod 4 then picks and signs them. sinCos(0) is (0, 1) exactly, which keeps hair at rest at rest.
HAIRGEN_LANES16 void sinCos(F x, F& s, F& c) {
  constexpr float kTwoOverPi = 0.636619772367581343076f;
  constexpr float kPiOver2[3] = {1.5703125f, 4.838705062866211e-4f, -4.371138828673793e-8f};
  constexpr float kRound = 12582912.0f;  // 1.5·2²³: adding it rounds to an integer, in the low bits
  constexpr float s0 = -0.16666655242443085f, s1 = 0.00833216030150652f, s2 = -0.00019515282474458218f;
  constexpr float c0 = 0.04166664555668831f, c1 = -0.001388736767694354f, c2 = 2.443845005473122e-05f;
  const F shifted = x * kTwoOverPi + kRound;
  const F k = shifted - kRound;
  const F r = ((x - k * kPiOver2[0]) - k * kPiOver2[1]) - k * kPiOver2[2];
  const F z = r * r;
  const F sr = r + r * z * (s0 + z * (s1 + z * s2));
  const F cr = 1.0f - 0.5f * z + z * z * (c0 + z * (c1 + z * c2));
  // k's low bits are the shifted sum's (two's complement: −1 is 3). Odd quadrants swap sin and cos;
  // quadrants 2 and 3 negate sin, 1 and 2 cos (a flip of the sign bit).
  const I q = __builtin_bit_cast(I, shifted) & 3, odd = -(q & 1);
  const I srBits = __builtin_bit_cast(I, sr), crBits = __builtin_bit_cast(I, cr);
  const I sinR = (odd & crBits) | (~odd & srBits), cosR = (odd & srBits) | (~odd & crBits);
  s = __builtin_bit_cast(F, sinR ^ ((q & 2) << 30));
  c = __builtin_bit_cast(F, cosR ^ (((q + 1) & 2) << 30));
}

}  // namespace hairgen::lanes16
