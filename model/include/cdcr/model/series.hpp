#pragma once
// Smooth scalar functions that appear in SE(3) exp/log and in the
// constant-curvature arc. Each has a removable singularity (0/0) at theta = 0
// and, computed naively, loses digits to cancellation near it. Below the
// switch-over point they are evaluated from their Taylor series, with enough
// terms that the truncation error is below double-precision rounding; above
// it, from formulas that have no cancellation there.

#include <cmath>

namespace cdcr::model::series {

// Below this angle the polynomial branches are used. At 0.5 rad the first
// omitted term of every series here is below 1e-18 relative.
template <typename S> constexpr S kSeriesSwitchRad = S(0.5);

// sin(x)/x. The direct form has no cancellation, only 0/0 at x = 0.
template <typename S> S sinc(S x) {
  const S x2 = x * x;
  if (std::abs(x) < S(1e-2)) {
    return S(1) - x2 / S(6) * (S(1) - x2 / S(20) * (S(1) - x2 / S(42)));
  }
  return std::sin(x) / x;
}

// (1 - cos x)/x^2, written as (sin(x/2)/(x/2))^2 / 2 so that no digits cancel.
template <typename S> S one_minus_cos_over_sq(S x) {
  const S half_sinc = sinc(x / S(2));
  return S(0.5) * half_sinc * half_sinc;
}

// (x - sin x)/x^3.
template <typename S> S x_minus_sin_over_cube(S x) {
  const S x2 = x * x;
  if (std::abs(x) < kSeriesSwitchRad<S>) {
    // sum_k (-1)^k x^(2k) / (2k+3)!
    return S(1) / S(6) +
           x2 * (S(-1) / S(120) +
                 x2 * (S(1) / S(5040) +
                       x2 * (S(-1) / S(362880) +
                             x2 * (S(1) / S(39916800) +
                                   x2 * (S(-1) / S(6227020800.0) + x2 * (S(1) / S(1307674368000.0)))))));
  }
  return (x - std::sin(x)) / (x2 * x);
}

// (1 - (x/2) cot(x/2)) / x^2: the W^2 coefficient of the inverse of the SE(3)
// left Jacobian of rotation, used by log. Finite on [0, pi] (1/pi^2 at pi).
template <typename S> S log_translation_coefficient(S x) {
  const S x2 = x * x;
  if (std::abs(x) < kSeriesSwitchRad<S>) {
    // sum_n |B_2n| x^(2n-2) / (2n)!, Bernoulli numbers B_2 .. B_14.
    return S(1) / S(12) +
           x2 * (S(1) / S(720) +
                 x2 * (S(1) / S(30240) +
                       x2 * (S(1) / S(1209600) +
                             x2 * (S(1) / S(47900160) +
                                   x2 * (S(691) / S(1307674368000.0) + x2 * (S(1) / S(74724249600.0)))))));
  }
  const S half = x / S(2);
  return (S(1) - half * std::cos(half) / std::sin(half)) / x2;
}

}  // namespace cdcr::model::series
