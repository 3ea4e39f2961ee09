#pragma once
// The GP mean's inner loop for 8 inputs (4 segments) on a Cortex-M7, in
// assembly. It is the same computation as GpCorrection's portable loop,
// operation for operation (squared distance, polynomial_gaussian, block sums
// in float, each block into the double sums), so the two give the same bits;
// the QEMU replay test checks that they do. What the assembly adds is register
// allocation: the query (s0-s7), the six block sums (s8-s13) and the kernel's
// constants (s14, s15, s24-s29) stay in registers for the whole loop, each
// training point and its alphas arrive with one VLDM each, and the block's
// first point initialises the sums. That is 44 instructions per training
// point where GCC's code for the C++ loop needed 57 (constants reloaded from
// the literal pool on every point).

#include <cstdint>

#include "cdcr/model/kernel_exp.hpp"

#if !(defined(__GNUC__) && !defined(__clang__) && defined(__ARM_ARCH_7EM__) && defined(__ARM_FP) && (__ARM_FP & 0x8))
#error "model/arch/fpv5 needs GCC targeting an Armv7E-M core with a double-precision FPU (check CDCR_MODEL_ARCH)"
#endif

namespace cdcr::model::arch::detail {

inline constexpr std::uint32_t kFpv5BlockPoints = 8;

// Distance of the next training point (8 floats at z) from the query, into s16.
#define CDCR_FPV5_DISTANCE                 \
  "vldmia %[z]!, {s16-s23}\n\t"            \
  "vsub.f32 s16, s0, s16\n\t"              \
  "vsub.f32 s17, s1, s17\n\t"              \
  "vsub.f32 s18, s2, s18\n\t"              \
  "vsub.f32 s19, s3, s19\n\t"              \
  "vsub.f32 s20, s4, s20\n\t"              \
  "vsub.f32 s21, s5, s21\n\t"              \
  "vsub.f32 s22, s6, s22\n\t"              \
  "vsub.f32 s23, s7, s23\n\t"              \
  "vmul.f32 s16, s16, s16\n\t"             \
  "vfma.f32 s16, s17, s17\n\t"             \
  "vfma.f32 s16, s18, s18\n\t"             \
  "vfma.f32 s16, s19, s19\n\t"             \
  "vfma.f32 s16, s20, s20\n\t"             \
  "vfma.f32 s16, s21, s21\n\t"             \
  "vfma.f32 s16, s22, s22\n\t"             \
  "vfma.f32 s16, s23, s23\n\t"

// polynomial_gaussian(s16) into s23, step for step.
#define CDCR_FPV5_GAUSSIAN                 \
  "vminnm.f32 s16, s16, s24\n\t"           \
  "vmul.f32 s17, s16, s14\n\t"             \
  "vcvtr.s32.f32 s17, s17\n\t"             \
  "vmov %[k], s17\n\t"                     \
  "vcvt.f32.s32 s17, s17\n\t"              \
  "vfma.f32 s16, s17, s15\n\t"             \
  "vmul.f32 s18, s16, s16\n\t"             \
  "vmov.f32 s19, s25\n\t"                  \
  "vfma.f32 s19, s16, s26\n\t"             \
  "vmov.f32 s20, s27\n\t"                  \
  "vfma.f32 s20, s16, s28\n\t"             \
  "vfma.f32 s20, s18, s29\n\t"             \
  "vfma.f32 s19, s18, s20\n\t"             \
  "vmov.f32 s21, #-0.5\n\t"                \
  "vfma.f32 s21, s16, s19\n\t"             \
  "vmov.f32 s22, #1.0\n\t"                 \
  "vfma.f32 s22, s16, s21\n\t"             \
  "vmov %[p], s22\n\t"                     \
  "add %[p], %[p], %[k], lsl #23\n\t"      \
  "vmov s23, %[p]\n\t"

// The point's six terms: the first point of a block sets the sums, the
// others add to them.
#define CDCR_FPV5_TERMS(op)                \
  "vldmia %[a]!, {s16-s21}\n\t"            \
  op " s8, s23, s16\n\t"                   \
  op " s9, s23, s17\n\t"                   \
  op " s10, s23, s18\n\t"                  \
  op " s11, s23, s19\n\t"                  \
  op " s12, s23, s20\n\t"                  \
  op " s13, s23, s21\n\t"

#define CDCR_FPV5_POINT(op) CDCR_FPV5_DISTANCE CDCR_FPV5_GAUSSIAN CDCR_FPV5_TERMS(op)

// The block's sums into the six doubles at t, two at a time (d8-d11 are
// s16-s23, free between points).
#define CDCR_FPV5_BLOCK_INTO_DOUBLES(first, second) \
  "vldmia %[t], {d8-d9}\n\t"                         \
  "vcvt.f64.f32 d10, " first "\n\t"                  \
  "vcvt.f64.f32 d11, " second "\n\t"                 \
  "vadd.f64 d8, d8, d10\n\t"                         \
  "vadd.f64 d9, d9, d11\n\t"                         \
  "vstmia %[t]!, {d8-d9}\n\t"

// `blocks` (at least 1) blocks of kFpv5BlockPoints training points, 8 inputs
// each; advances inputs and alpha past them.
inline void gp_mean_blocks_fpv5(const float* query, const float*& inputs, const float*& alpha,
                                std::uint32_t blocks, double* sums) {
  using namespace gaussian_constants;
  static constexpr float kConstants[8] = {kMinusHalfLog2e, kTwoLn2, kClamp, kB2, kB3, kB4, kB5, kB6};
  std::int32_t k_bits;
  std::int32_t p_bits;
  asm volatile(
      "vldmia %[q], {s0-s7}\n\t"
      "vldr s14, [%[c]]\n\t"
      "vldr s15, [%[c], #4]\n\t"
      "vldr s24, [%[c], #8]\n\t"
      "vldr s25, [%[c], #12]\n\t"
      "vldr s26, [%[c], #16]\n\t"
      "vldr s27, [%[c], #20]\n\t"
      "vldr s28, [%[c], #24]\n\t"
      "vldr s29, [%[c], #28]\n\t"
      "1:\n\t"
      CDCR_FPV5_POINT("vmul.f32")
      CDCR_FPV5_POINT("vfma.f32")
      CDCR_FPV5_POINT("vfma.f32")
      CDCR_FPV5_POINT("vfma.f32")
      CDCR_FPV5_POINT("vfma.f32")
      CDCR_FPV5_POINT("vfma.f32")
      CDCR_FPV5_POINT("vfma.f32")
      CDCR_FPV5_POINT("vfma.f32")
      CDCR_FPV5_BLOCK_INTO_DOUBLES("s8", "s9")
      CDCR_FPV5_BLOCK_INTO_DOUBLES("s10", "s11")
      CDCR_FPV5_BLOCK_INTO_DOUBLES("s12", "s13")
      "sub %[t], %[t], #48\n\t"
      "subs %[n], %[n], #1\n\t"
      "bne 1b\n\t"
      : [z] "+r"(inputs), [a] "+r"(alpha), [n] "+r"(blocks), [t] "+r"(sums), [k] "=&r"(k_bits), [p] "=&r"(p_bits)
      : [q] "r"(query), [c] "r"(kConstants)
      : "d0", "d1", "d2", "d3", "d4", "d5", "d6", "d7", "d8", "d9", "d10", "d11", "d12", "d13", "d14", "d15",
        "cc", "memory");
}

#undef CDCR_FPV5_DISTANCE
#undef CDCR_FPV5_GAUSSIAN
#undef CDCR_FPV5_TERMS
#undef CDCR_FPV5_POINT
#undef CDCR_FPV5_BLOCK_INTO_DOUBLES

}  // namespace cdcr::model::arch::detail
