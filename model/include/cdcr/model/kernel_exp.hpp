#pragma once
// The squared-exponential kernel's one transcendental function,
// gaussian(y) = exp(-y / 2) for a squared distance y >= 0, evaluated N times
// per cycle by the GP correction. In double it is std::exp (the trainer, the
// host's reference path). In float on a Cortex-M FPU it is
// polynomial_gaussian below: newlib's expf checks for overflow, NaN and errno
// on every call and cost a third of the loop there, for arguments that here
// are always finite and non-positive. Elsewhere (x86-64, AArch64 hosts) the C
// library's expf is faster than the polynomial, and within 1 ulp; it gets
// the polynomial's clamp.
//
// polynomial_gaussian: y clamped to 173 (e^-86.5, the bottom of the normal
// floats; beyond it every term is negligible), k = round(-y log2(e) / 2) with
// ties to even, v = y + 2 k ln 2 (|v| <= ln 2), exp(-v / 2) from a degree-6
// polynomial fitted for relative error (3e-9 in exact arithmetic), and 2^k
// put into the exponent bits. Within 1.5 ulp of exp(-y/2) for y <= 40 and 5
// ulp down to e^-86.5, where k ln 2 carries the float rounding of ln 2
// (tested against std::exp in host_tests/model/kernel_exp_test.cpp). The boards' assembly
// loops (model/arch/fpv4/.../gp_point_asm.hpp) perform the same operations in the same order
// and so give the same bits.

#include <cmath>
#include <cstdint>
#include <cstring>

namespace cdcr::model {

// a * b + c, fused where the FPU has the instruction (every Cortex-M4F/M7):
// one instruction instead of two, and one rounding. Elsewhere (a plain x86-64
// build has no FMA unit and std::fma would be a library call) the two
// operations, rounded separately.
template <typename S>
inline S multiply_add(S a, S b, S c) {
#if defined(__ARM_FEATURE_FMA)
  return std::fma(a, b, c);
#else
  return a * b + c;
#endif
}

namespace gaussian_constants {
inline constexpr float kClamp = 173.0f;
inline constexpr float kMinusHalfLog2e = -0.721347520f;  // -log2(e) / 2
inline constexpr float kTwoLn2 = 1.38629436f;
// exp(-v/2) = 1 + v (-1/2 + v (b2 + b3 v + v^2 (b4 + b5 v + b6 v^2)))
inline constexpr float kB2 = 0.124999985f;
inline constexpr float kB3 = -0.0208331496f;
inline constexpr float kB4 = 0.00260427454f;
inline constexpr float kB5 = -0.000261524139f;
inline constexpr float kB6 = 2.1585045e-05f;
// In the order the boards' assembly loops load them (CDCR_GP_ASM_LOAD_CONSTANTS
// in model/arch/fpv4/.../gp_point_asm.hpp).
inline constexpr float kAssemblyOrder[8] = {kMinusHalfLog2e, kTwoLn2, kClamp, kB2, kB3, kB4, kB5, kB6};
}  // namespace gaussian_constants

// Fused multiply-adds throughout (std::fma is one VFMA on the boards), so
// that a host computes the same bits as a board when it tests this.
inline float polynomial_gaussian(float distance_sq) {
  using namespace gaussian_constants;
  constexpr float kShifter = 12582912.0f;  // 1.5 * 2^23: adding it rounds to an integer, ties to even
  // Also maps NaN to the clamp, as the FPU's VMINNM does.
  const float y = distance_sq < kClamp ? distance_sq : kClamp;
  const float z = y * kMinusHalfLog2e;
  const float k = (z + kShifter) - kShifter;
  const auto k_integer = static_cast<std::int32_t>(k);
  const float v = std::fma(k, kTwoLn2, y);
  const float v2 = v * v;
  const float b = std::fma(v, kB3, kB2);
  float c = std::fma(v, kB5, kB4);
  c = std::fma(v2, kB6, c);
  const float e = std::fma(v2, c, b);
  const float d = std::fma(v, e, -0.5f);
  const float p = std::fma(v, d, 1.0f);
  std::int32_t bits;
  std::memcpy(&bits, &p, sizeof(bits));
  bits += static_cast<std::int32_t>(static_cast<std::uint32_t>(k_integer) << 23);
  float result;
  std::memcpy(&result, &bits, sizeof(result));
  return result;
}

inline float gaussian(float distance_sq) {
#if defined(__arm__) && defined(__ARM_FP)
  return polynomial_gaussian(distance_sq);
#else
  // The polynomial's clamp: beyond it the C library's expf takes its
  // underflow path (subnormal results, errno), which made a mean over far
  // training points half as fast again, for terms that are negligible.
  return std::exp(-0.5f * (distance_sq < gaussian_constants::kClamp ? distance_sq : gaussian_constants::kClamp));
#endif
}

inline double gaussian(double distance_sq) { return std::exp(-0.5 * distance_sq); }

}  // namespace cdcr::model
