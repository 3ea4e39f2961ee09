#pragma once
// exp(x) for x <= 0, the one transcendental function of the GP correction's
// inner loop. In double it is std::exp (the trainer, the host's reference
// path). In float on a Cortex-M FPU it is polynomial_exp below: newlib's expf
// checks for overflow, NaN and errno on every call and costs a third of the
// loop there, for arguments that here are always finite and non-positive.
// Elsewhere (x86-64, AArch64 hosts) the C library's expf is already faster
// than the polynomial, and within 1 ulp.
//
// polynomial_exp: x = k ln2 + r with |r| <= ln2/2 (k rounded with the 1.5 * 2^23
// shifter, ln2 split in two so k ln2 is exact), e^r from the degree-7
// minimax-style polynomial below (Cephes' expf coefficients), and 2^k put
// into the exponent bits. Relative error below 2 ulp over [-87, 0] (tested
// against std::exp in host_tests/model/kernel_exp_test.cpp); below -86.5
// (e^-86.5 = 2.7e-38, the bottom of the normal floats) the result is 0, or
// e^-86.5 where the FPU clamps in one instruction.

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

inline float polynomial_exp(float x) {
  constexpr float kLowest = -86.5f;  // 2^k stays a normal float
  constexpr float kLog2e = 1.44269504088896341f;
  constexpr float kShifter = 12582912.0f;  // 1.5 * 2^23: adding it rounds to an integer
  constexpr float kLn2High = 0.693359375f;  // few mantissa bits, so k * kLn2High is exact
  constexpr float kLn2Low = -2.12194440e-4f;
#if defined(__ARM_FEATURE_NUMERIC_MAXMIN) || (defined(__ARM_ARCH_7EM__) && defined(__ARM_FP) && (__ARM_FP & 0x8))
  // One VMAXNM (FPv5, as on the Cortex-M7): the clamped value's e^-86.5 is
  // as good as 0 here.
  x = __builtin_fmaxf(x, kLowest);
#else
  if (!(x >= kLowest)) return 0.0f;
#endif
  const float shifted = multiply_add(x, kLog2e, kShifter);
  const float k = shifted - kShifter;
  float r = multiply_add(k, -kLn2High, x);
  r = multiply_add(k, -kLn2Low, r);
  float p = 1.9875691500e-4f;
  p = multiply_add(p, r, 1.3981999507e-3f);
  p = multiply_add(p, r, 8.3334519073e-3f);
  p = multiply_add(p, r, 4.1665795894e-2f);
  p = multiply_add(p, r, 1.6666665459e-1f);
  p = multiply_add(p, r, 5.0000001201e-1f);
  p = multiply_add(p, r * r, r + 1.0f);
  // k is the integer in the low mantissa bits of `shifted`.
  std::int32_t k_bits;
  std::memcpy(&k_bits, &shifted, sizeof(k_bits));
  std::int32_t k_integer = k_bits - 0x4B400000;  // the bits of kShifter
  std::int32_t p_bits;
  std::memcpy(&p_bits, &p, sizeof(p_bits));
  p_bits += static_cast<std::int32_t>(static_cast<std::uint32_t>(k_integer) << 23);
  float result;
  std::memcpy(&result, &p_bits, sizeof(result));
  return result;
}

inline float kernel_exp(float x) {
#if defined(__arm__) && defined(__ARM_FP)
  return polynomial_exp(x);
#else
  return std::exp(x);
#endif
}

inline double kernel_exp(double x) { return std::exp(x); }

}  // namespace cdcr::model
