// Forward-mode derivatives: a Dual carries a value and its derivatives along N directions, and every
// operation below applies the chain rule exactly, so code written once for a scalar type T gives the
// energy with T = double and the energy with its gradient with T = Dual<N> (the quasi-Newton
// minimiser's analytic derivatives of the Super-Helix closed forms). The generic helpers at the end
// (Vec3, crossOf, dotOf, lengthOf, minOf) compute, for double, exactly what glm's cross, dot and length
// and std::min compute, operation for operation, so templating a double routine keeps its bits.
#pragma once

#include <array>
#include <cmath>

#include <glm/glm.hpp>

namespace hairgen {

// Every operation is forced inline: each is a short loop over N doubles, and a call per operation
// (GCC inlines few of them by itself) costs more than the loop.
#define HAIRGEN_DUAL [[gnu::always_inline]] inline

template <int N>
struct Dual {
  double v = 0.0;
  std::array<double, N> d{};

  Dual() = default;
  Dual(double value) : v(value) {}  // NOLINT(google-explicit-constructor): a constant converts freely
  // The k-th coordinate: its derivative along direction k is 1.
  static Dual variable(double value, int k) {
    Dual x(value);
    x.d[static_cast<size_t>(k)] = 1.0;
    return x;
  }
  Dual& operator+=(const Dual& b) { return *this = *this + b; }
  Dual& operator-=(const Dual& b) { return *this = *this - b; }
  Dual& operator*=(const Dual& b) { return *this = *this * b; }

  // d(a·b) = a·db + b·da and friends, with the derivative part scaled once per operand.
  HAIRGEN_DUAL friend Dual operator+(const Dual& a, const Dual& b) {
    Dual r(a.v + b.v);
    for (int k = 0; k < N; ++k) r.d[k] = a.d[k] + b.d[k];
    return r;
  }
  HAIRGEN_DUAL friend Dual operator-(const Dual& a, const Dual& b) {
    Dual r(a.v - b.v);
    for (int k = 0; k < N; ++k) r.d[k] = a.d[k] - b.d[k];
    return r;
  }
  HAIRGEN_DUAL friend Dual operator-(const Dual& a) { return a * -1.0; }
  HAIRGEN_DUAL friend Dual operator*(const Dual& a, const Dual& b) {
    Dual r(a.v * b.v);
    for (int k = 0; k < N; ++k) r.d[k] = a.d[k] * b.v + a.v * b.d[k];
    return r;
  }
  HAIRGEN_DUAL friend Dual operator/(const Dual& a, const Dual& b) {
    const double inv = 1.0 / b.v, q = a.v * inv;
    Dual r(a.v / b.v);
    for (int k = 0; k < N; ++k) r.d[k] = (a.d[k] - q * b.d[k]) * inv;
    return r;
  }
  HAIRGEN_DUAL friend Dual operator+(const Dual& a, double b) {
    Dual r = a;
    r.v += b;
    return r;
  }
  HAIRGEN_DUAL friend Dual operator+(double a, const Dual& b) { return b + a; }
  HAIRGEN_DUAL friend Dual operator-(const Dual& a, double b) { return a + -b; }
  HAIRGEN_DUAL friend Dual operator-(double a, const Dual& b) {
    Dual r(a - b.v);
    for (int k = 0; k < N; ++k) r.d[k] = -b.d[k];
    return r;
  }
  HAIRGEN_DUAL friend Dual operator*(const Dual& a, double b) {
    Dual r(a.v * b);
    for (int k = 0; k < N; ++k) r.d[k] = a.d[k] * b;
    return r;
  }
  HAIRGEN_DUAL friend Dual operator*(double a, const Dual& b) { return b * a; }
  HAIRGEN_DUAL friend Dual operator/(const Dual& a, double b) {
    Dual r(a.v / b);
    const double inv = 1.0 / b;
    for (int k = 0; k < N; ++k) r.d[k] = a.d[k] * inv;
    return r;
  }
  HAIRGEN_DUAL friend Dual operator/(double a, const Dual& b) { return Dual(a) / b; }

  // Comparisons compare values: a branch on them picks the same closed form as the double code.
  HAIRGEN_DUAL friend bool operator<(const Dual& a, const Dual& b) { return a.v < b.v; }
  HAIRGEN_DUAL friend bool operator<(const Dual& a, double b) { return a.v < b; }
  HAIRGEN_DUAL friend bool operator>(const Dual& a, double b) { return a.v > b; }
  HAIRGEN_DUAL friend bool operator>=(const Dual& a, double b) { return a.v >= b; }

  HAIRGEN_DUAL friend Dual sqrt(const Dual& a) {
    // At 0 the derivative is taken as 0: hairgen takes √ of |W|², whose gradient vanishes there,
    // and every closed form that uses |W| is smooth in |W|² (see super_helix.h).
    const double s = std::sqrt(a.v);
    return chain(a, s, s > 0.0 ? 0.5 / s : 0.0);
  }
  HAIRGEN_DUAL friend Dual sin(const Dual& a) { return chain(a, std::sin(a.v), std::cos(a.v)); }
  HAIRGEN_DUAL friend Dual cos(const Dual& a) { return chain(a, std::cos(a.v), -std::sin(a.v)); }

 private:
  // f(a) given f(a.v) and f'(a.v).
  HAIRGEN_DUAL static Dual chain(const Dual& a, double value, double slope) {
    Dual r(value);
    for (int k = 0; k < N; ++k) r.d[k] = a.d[k] * slope;
    return r;
  }
};

inline double valueOf(double x) {
  return x;
}
template <int N>
double valueOf(const Dual<N>& x) {
  return x.v;
}

template <class T>
using Vec3 = glm::vec<3, T, glm::defaultp>;

template <class T>
glm::dvec3 valueOf(const Vec3<T>& v) {
  return {valueOf(v.x), valueOf(v.y), valueOf(v.z)};
}

// glm's vector-by-scalar operators want both of one type; a double times a vector of Duals scales
// only the derivatives' parts it must.
template <int N>
HAIRGEN_DUAL Vec3<Dual<N>> operator*(double s, const Vec3<Dual<N>>& v) {
  return {v.x * s, v.y * s, v.z * s};
}

template <class T>
HAIRGEN_DUAL Vec3<T> crossOf(const Vec3<T>& x, const Vec3<T>& y) {
  return {x.y * y.z - y.y * x.z, x.z * y.x - y.z * x.x, x.x * y.y - y.x * x.y};
}

template <class T, class U>
HAIRGEN_DUAL T dotOf(const Vec3<T>& a, const Vec3<U>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

template <class T>
HAIRGEN_DUAL T lengthOf(const Vec3<T>& v) {
  using std::sqrt;
  return sqrt(dotOf(v, v));
}

template <class T>
const T& minOf(const T& a, const T& b) {
  return (b < a) ? b : a;
}

}  // namespace hairgen
