// The symmetric tridiagonal solve of the springs' stretch constraints (spring_dynamics.cpp, and its
// vector lanes in spring_lanes.cpp): one template for a double and a vector of them, so both kernels
// make the same operations in the same order (their bits must agree).
#pragma once

#include <cstdint>

namespace hairgen {

// Thomas' algorithm on rows 1..n (n >= 1): diagonal `diag`, off-diagonal `upper` (row j, column j + 1),
// right-hand side `rhs`, which becomes the solution; `diag` is overwritten by the elimination and
// `inverseDiag` receives its inverses. One division a row.
template <class T>
[[gnu::always_inline]] inline void solveTridiagonal(const T* upper, T* diag, T* rhs, T* inverseDiag,
                                                    uint32_t n) {
  inverseDiag[1] = 1.0 / diag[1];
  for (uint32_t j = 2; j <= n; ++j) {
    const T m = upper[j - 1] * inverseDiag[j - 1];
    diag[j] -= m * upper[j - 1];
    rhs[j] -= m * rhs[j - 1];
    inverseDiag[j] = 1.0 / diag[j];
  }
  rhs[n] *= inverseDiag[n];
  for (uint32_t j = n - 1; j >= 1; --j) rhs[j] = (rhs[j] - upper[j] * rhs[j + 1]) * inverseDiag[j];
}

}  // namespace hairgen
