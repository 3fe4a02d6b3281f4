// The sin and cos of a small turn δ by their Taylor series, for Anjyo's step, which turns the carried
// sin and cos of each angle by its step's increment instead of evaluating new ones. One definition for
// the strand-by-strand step and the vector one (anjyo_lanes.cpp), which must agree bit for bit: `T` is
// double or a vector of doubles.
#pragma once

namespace hairgen {

// Below this |δ| (radians) the series below is exact to rounding: its first omitted terms, δ¹³/13! and
// δ¹⁴/14!, are below 1e-18 of the result there. Beyond it the library's sin and cos are used.
constexpr double kTurnSeriesReach = 0.2;

template <class T>
inline void turnSeries(T delta, T& sinDelta, T& cosDelta) {
  const T d2 = delta * delta;
  sinDelta =
      delta *
      (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0 * (1.0 - d2 / 42.0 * (1.0 - d2 / 72.0 * (1.0 - d2 / 110.0)))));
  cosDelta =
      1.0 -
      d2 / 2.0 *
          (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0 * (1.0 - d2 / 56.0 * (1.0 - d2 / 90.0 * (1.0 - d2 / 132.0)))));
}

}  // namespace hairgen
