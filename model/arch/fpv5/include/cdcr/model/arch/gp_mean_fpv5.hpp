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

#include "cdcr/model/arch/gp_point_asm.hpp"
#include "cdcr/model/kernel_exp.hpp"

#if !(defined(__GNUC__) && !defined(__clang__) && defined(__ARM_ARCH_7EM__) && defined(__ARM_FP) && (__ARM_FP & 0x8))
#error "model/arch/fpv5 needs GCC targeting an Armv7E-M core with a double-precision FPU (check CDCR_MODEL_ARCH)"
#endif

namespace cdcr::model::arch::detail {

inline constexpr std::uint32_t kFpv5BlockPoints = 8;

// The kernel's clamp: VMINNM returns the number when the other operand is
// NaN, so NaN goes to 173 too, as polynomial_gaussian's comparison.
#define CDCR_FPV5_POINT(op)                                                                        \
  CDCR_GP_ASM_DISTANCE "vminnm.f32 s16, s16, s24\n\t" CDCR_GP_ASM_GAUSSIAN_OF_CLAMPED \
      CDCR_GP_ASM_TERMS(op)

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
  std::int32_t k_bits;
  std::int32_t p_bits;
  asm volatile(
      "vldmia %[q], {s0-s7}\n\t"
      CDCR_GP_ASM_LOAD_CONSTANTS
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
      : [q] "r"(query), [c] "r"(gaussian_constants::kAssemblyOrder)
      : "d0", "d1", "d2", "d3", "d4", "d5", "d6", "d7", "d8", "d9", "d10", "d11", "d12", "d13", "d14", "d15",
        "cc", "memory");
}

#undef CDCR_GP_ASM_DISTANCE
#undef CDCR_GP_ASM_GAUSSIAN_OF_CLAMPED
#undef CDCR_GP_ASM_TERMS
#undef CDCR_GP_ASM_LOAD_CONSTANTS
#undef CDCR_FPV5_POINT
#undef CDCR_FPV5_BLOCK_INTO_DOUBLES

}  // namespace cdcr::model::arch::detail
