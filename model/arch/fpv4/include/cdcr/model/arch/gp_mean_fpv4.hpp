#pragma once
// The GP mean's inner loop for 8 inputs (4 segments) on a Cortex-M4F, in
// assembly: the Cortex-M7's loop (model/arch/fpv5/.../gp_mean_fpv5.hpp)
// without what FPv4-SP lacks. The kernel's clamp is a compare and a
// conditional move instead of VMINNM (the same result, NaN included), and
// each block's float sums go into compensated float sums (CompensatedFloat's
// TwoSum, operation for operation) instead of doubles. So it computes what
// GpCorrection's portable loop computes, bit for bit; the QEMU replay test
// checks that it does. As on the M7, the query, the block sums and the
// kernel's constants stay in registers for the whole loop, and a training
// point and its alphas arrive with one VLDM each: 47 instructions a point
// and 7 more for the compensated sums, where GCC's code for the C++ loop
// needs about 72.

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "cdcr/model/compensated_float.hpp"
#include "cdcr/model/arch/gp_point_asm.hpp"
#include "cdcr/model/kernel_exp.hpp"

#if !(defined(__GNUC__) && !defined(__clang__) && defined(__ARM_ARCH_7EM__) && defined(__ARM_FP) && (__ARM_FP & 0x4))
#error "model/arch/fpv4 needs GCC targeting an Armv7E-M core with a single-precision FPU (check CDCR_MODEL_ARCH)"
#endif

namespace cdcr::model::arch::detail {

static_assert(std::is_standard_layout_v<CompensatedFloat> && sizeof(CompensatedFloat) == 2 * sizeof(float) &&
                  offsetof(CompensatedFloat, sum) == 0 && offsetof(CompensatedFloat, compensation) == sizeof(float),
              "the assembly reads CompensatedFloat as {sum, compensation}");

inline constexpr std::uint32_t kFpv4BlockPoints = 8;

// The kernel's clamp: unless s16 < 173 (N is set only by an ordered
// less-than), s16 = 173, so NaN too, as polynomial_gaussian's comparison.
#define CDCR_FPV4_CLAMP                    \
  "vcmp.f32 s16, s24\n\t"                  \
  "vmrs APSR_nzcv, fpscr\n\t"              \
  "it pl\n\t"                              \
  "vmovpl.f32 s16, s24\n\t"

#define CDCR_FPV4_POINT(op) \
  CDCR_GP_ASM_DISTANCE CDCR_FPV4_CLAMP CDCR_GP_ASM_GAUSSIAN_OF_CLAMPED CDCR_GP_ASM_TERMS(op)

// CompensatedFloat's += of the block sum `term` into {sum, compensation}:
// t = sum + term; z = t - sum;
// compensation += (sum - (t - z)) + (term - z); sum = t.
#define CDCR_FPV4_TWO_SUM(term, sum, compensation) \
  "vadd.f32 s20, " sum ", " term "\n\t"             \
  "vsub.f32 s21, s20, " sum "\n\t"                  \
  "vsub.f32 s22, s20, s21\n\t"                      \
  "vsub.f32 s22, " sum ", s22\n\t"                  \
  "vsub.f32 s23, " term ", s21\n\t"                 \
  "vadd.f32 s22, s22, s23\n\t"                      \
  "vadd.f32 " compensation ", " compensation ", s22\n\t" \
  "vmov.f32 " sum ", s20\n\t"

// Two of the block's sums into the compensated sums at t (s16-s23 are free
// between points).
#define CDCR_FPV4_BLOCK_INTO_SUMS(first, second)   \
  "vldmia %[t], {s16-s19}\n\t"                      \
  CDCR_FPV4_TWO_SUM(first, "s16", "s17")            \
  CDCR_FPV4_TWO_SUM(second, "s18", "s19")           \
  "vstmia %[t]!, {s16-s19}\n\t"

// `blocks` (at least 1) blocks of kFpv4BlockPoints training points, 8 inputs
// each; advances inputs and alpha past them.
inline void gp_mean_blocks_fpv4(const float* query, const float*& inputs, const float*& alpha,
                                std::uint32_t blocks, CompensatedFloat* sums) {
  float* sums_data = &sums[0].sum;
  std::int32_t k_bits;
  std::int32_t p_bits;
  asm volatile(
      "vldmia %[q], {s0-s7}\n\t"
      CDCR_GP_ASM_LOAD_CONSTANTS
      "1:\n\t"
      CDCR_FPV4_POINT("vmul.f32")
      CDCR_FPV4_POINT("vfma.f32")
      CDCR_FPV4_POINT("vfma.f32")
      CDCR_FPV4_POINT("vfma.f32")
      CDCR_FPV4_POINT("vfma.f32")
      CDCR_FPV4_POINT("vfma.f32")
      CDCR_FPV4_POINT("vfma.f32")
      CDCR_FPV4_POINT("vfma.f32")
      CDCR_FPV4_BLOCK_INTO_SUMS("s8", "s9")
      CDCR_FPV4_BLOCK_INTO_SUMS("s10", "s11")
      CDCR_FPV4_BLOCK_INTO_SUMS("s12", "s13")
      "sub %[t], %[t], #48\n\t"
      "subs %[n], %[n], #1\n\t"
      "bne 1b\n\t"
      : [z] "+r"(inputs), [a] "+r"(alpha), [n] "+r"(blocks), [t] "+r"(sums_data), [k] "=&r"(k_bits),
        [p] "=&r"(p_bits)
      : [q] "r"(query), [c] "r"(gaussian_constants::kAssemblyOrder)
      : "s0", "s1", "s2", "s3", "s4", "s5", "s6", "s7", "s8", "s9", "s10", "s11", "s12", "s13", "s14", "s15",
        "s16", "s17", "s18", "s19", "s20", "s21", "s22", "s23", "s24", "s25", "s26", "s27", "s28", "s29", "cc",
        "memory");
}

#undef CDCR_GP_ASM_DISTANCE
#undef CDCR_GP_ASM_GAUSSIAN_OF_CLAMPED
#undef CDCR_GP_ASM_TERMS
#undef CDCR_GP_ASM_LOAD_CONSTANTS
#undef CDCR_FPV4_CLAMP
#undef CDCR_FPV4_POINT
#undef CDCR_FPV4_TWO_SUM
#undef CDCR_FPV4_BLOCK_INTO_SUMS

}  // namespace cdcr::model::arch::detail
