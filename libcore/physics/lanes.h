// Vectors of kLaneWidth doubles for the physics steps that take that many strands at once
// (anjyo_lanes.cpp, spring_lanes.cpp): GCC's vector extensions, with glm's arithmetic lane by lane, so a
// lane computes the bits the strand-by-strand code computes (the files using them are built without
// contraction into fused multiply-adds). Include only in files whose functions that use them are built
// for AVX-512 (gnu::target), the instruction set the lanes are written for.
#pragma once

#include <cstddef>

#include <immintrin.h>

#include <glm/glm.hpp>

namespace hairgen::lanes {

constexpr size_t kLaneWidth = 8;

// Keep lanes in registers and in arrays local to a function built for AVX-512, never in a std::vector: GCC
// aligns a vector type only as far as the default target's widest register, and heap memory would be
// misaligned for the AVX-512 code's loads.
using Vd = double __attribute__((vector_size(kLaneWidth * sizeof(double))));
using Vm = decltype(Vd{} < Vd{});  // a comparison's lanes: all ones or zero

struct V3 {
  Vd x, y, z;
};

// Every lane function is built for AVX-512, the instruction set its callers are built for.
#define HAIRGEN_LANE [[gnu::always_inline, gnu::target("avx512f,avx512dq")]] inline
// The same for a lambda (after its parameters), which does not take its function's target.
#define HAIRGEN_LANE_LAMBDA __attribute__((always_inline, target("avx512f,avx512dq")))

// Every lane v (a broadcast: −0 stays −0, where 0 + v would make it +0 and cost a scalar add).
HAIRGEN_LANE Vd splat(double v) {
  Vd r;
  for (size_t l = 0; l < kLaneWidth; ++l) r[l] = v;
  return r;
}
HAIRGEN_LANE V3 splat(const glm::dvec3& v) {
  return {splat(v.x), splat(v.y), splat(v.z)};
}
HAIRGEN_LANE V3 load(const double (&v)[3][kLaneWidth]) {
  V3 r;
  __builtin_memcpy(&r.x, v[0], sizeof(Vd));
  __builtin_memcpy(&r.y, v[1], sizeof(Vd));
  __builtin_memcpy(&r.z, v[2], sizeof(Vd));
  return r;
}
// Floats widened to doubles (exactly), and doubles rounded to floats as a cast does, lane by lane.
using Vf = float __attribute__((vector_size(kLaneWidth * sizeof(float))));
HAIRGEN_LANE V3 load(const float (&v)[3][kLaneWidth]) {
  Vf f[3];
  __builtin_memcpy(f, v, sizeof(f));
  return {__builtin_convertvector(f[0], Vd), __builtin_convertvector(f[1], Vd),
          __builtin_convertvector(f[2], Vd)};
}
HAIRGEN_LANE Vf toFloats(Vd v) {
  return __builtin_convertvector(v, Vf);
}
HAIRGEN_LANE Vd loadLanes(const double* v) {
  Vd r;
  __builtin_memcpy(&r, v, sizeof(Vd));
  return r;
}
HAIRGEN_LANE void storeLanes(double* to, Vd v) {
  __builtin_memcpy(to, &v, sizeof(Vd));
}
HAIRGEN_LANE Vd load(const double (&v)[kLaneWidth]) {
  return loadLanes(v);
}
// glm's operators, lane by lane: a scalar times a vector multiplies each component; dot is
// (x + y) + z of the products; cross is glm's (a.y b.z − b.y a.z, a.z b.x − b.z a.x, a.x b.y − b.x a.y).
HAIRGEN_LANE V3 operator+(const V3& a, const V3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
HAIRGEN_LANE V3 operator-(const V3& a, const V3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
HAIRGEN_LANE V3 operator*(Vd s, const V3& a) {
  return {s * a.x, s * a.y, s * a.z};
}
HAIRGEN_LANE V3 operator/(const V3& a, Vd s) {
  return {a.x / s, a.y / s, a.z / s};
}
HAIRGEN_LANE Vd dot(const V3& a, const V3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
HAIRGEN_LANE V3 cross(const V3& a, const V3& b) {
  return {a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y};
}
HAIRGEN_LANE Vd sqrt(Vd v) {
  for (size_t l = 0; l < kLaneWidth; ++l) v[l] = __builtin_sqrt(v[l]);
  return v;
}
HAIRGEN_LANE Vd select(Vm m, Vd a, Vd b) {
  return m ? a : b;
}
HAIRGEN_LANE Vm select(Vm m, Vm a, Vm b) {
  return m ? a : b;
}
HAIRGEN_LANE V3 select(Vm m, const V3& a, const V3& b) {
  return {m ? a.x : b.x, m ? a.y : b.y, m ? a.z : b.z};
}
// Comparisons lane by lane as single AVX-512 instructions: GCC splits a comparison of double vectors
// (`a < b`) into one scalar compare per lane in large functions.
template <int kPredicate>
HAIRGEN_LANE Vm compare(Vd a, Vd b) {
  static_assert(kLaneWidth == 8);
  return Vm(_mm512_movm_epi64(_mm512_cmp_pd_mask(__m512d(a), __m512d(b), kPredicate)));
}
HAIRGEN_LANE Vm less(Vd a, Vd b) {  // a < b (false where either is NaN)
  return compare<_CMP_LT_OQ>(a, b);
}
HAIRGEN_LANE Vm lessEqual(Vd a, Vd b) {  // a <= b (false where either is NaN)
  return compare<_CMP_LE_OQ>(a, b);
}
HAIRGEN_LANE Vm greater(Vd a, Vd b) {  // a > b (false where either is NaN)
  return compare<_CMP_GT_OQ>(a, b);
}
// Lanes where v != 0 (NaN included).
HAIRGEN_LANE Vm nonZero(Vd v) {
  return compare<_CMP_NEQ_UQ>(v, Vd{});
}
HAIRGEN_LANE Vd abs(Vd v) {
  return v < 0.0 ? -v : v;
}
HAIRGEN_LANE glm::dvec3 lane(const V3& v, size_t l) {
  return {v.x[l], v.y[l], v.z[l]};
}
HAIRGEN_LANE void setLane(V3& v, size_t l, const glm::dvec3& to) {
  v.x[l] = to.x;
  v.y[l] = to.y;
  v.z[l] = to.z;
}

}  // namespace hairgen::lanes
