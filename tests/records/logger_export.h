#pragma once

// Logger exports written from a closed-form free decay, so that every value read back can be
// checked against the exact one in SI: y(t) = A e^{-zeta w t} cos(w_d t) + offset.

#include <fmt/format.h>

#include <cmath>
#include <functional>
#include <string>

namespace mbid::testing {

struct Decay {
  // About the reference crane's first mode (1.5 Hz, 2 % damping): a realistic record shape.
  double frequency_hz = 1.5;
  double damping_ratio = 0.02;
  double amplitude = 2.0;  // in the file's unit
  double offset = 0.5;     // a sensor's zero offset, in the file's unit

  double operator()(double t) const {
    const double w = 2 * M_PI * frequency_hz;
    const double wd = w * std::sqrt(1 - damping_ratio * damping_ratio);
    return amplitude * std::exp(-damping_ratio * w * t) * std::cos(wd * t) + offset;
  }
  // A bound on |y''|: (sigma + w_d)^2 A >= |d^2/dt^2 A e^{-sigma t} cos(w_d t)|.
  double SecondDerivativeBound() const {
    const double w = 2 * M_PI * frequency_hz;
    return std::pow(damping_ratio * w + w, 2) * std::abs(amplitude);
  }
};

// One text export: `rows` rows of `row(j)` between `head` (preamble, header, units row) and
// the end; lines end with `eol`.
inline std::string MakeExport(const std::string& head, int rows,
                              const std::function<std::string(int)>& row,
                              const std::string& eol = "\n") {
  std::string text = head;
  for (int j = 0; j < rows; ++j) text += row(j) + eol;
  return text;
}

// A number printed with 9 significant digits (relative rounding error <= 5e-9), with a
// decimal comma when asked (German loggers).
inline std::string Print(double value, bool decimal_comma = false) {
  std::string text = fmt::format("{:.9g}", value);
  if (decimal_comma) {
    for (char& c : text) {
      if (c == '.') c = ',';
    }
  }
  return text;
}

}  // namespace mbid::testing
