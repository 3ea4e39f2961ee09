#pragma once
// GpCorrection's loops on a Cortex-M with a single-precision FPU (FPv4-SP,
// the Cortex-M4F; FPv5 builds on it): the portable loops with block loads,
// and the mean's loop for 8 inputs (4 segments) with compensated float sums
// in assembly (gp_mean_fpv4.hpp).
//
// On such a core GCC issues one VLDR per float; VLDMIA moves a whole training
// point (or its six alphas) in one instruction, about a fifth of the loop's
// instructions. The registers are fixed (s16 up) only at the load; the
// compiler allocates everything else around them. The image's blocks are
// 8-byte aligned, more than VLDMIA's word alignment needs. Only the
// instructions change: the arithmetic, and so every bit of the result, is
// the portable loop's.

#if !(defined(__GNUC__) && !defined(__clang__) && defined(__arm__) && defined(__ARM_FP) && (__ARM_FP & 0x4))
#error "model/arch/fpv4 needs GCC targeting an Arm core with a single-precision FPU (check CDCR_MODEL_ARCH)"
#endif

#include <cstdint>
#include <type_traits>

#include "cdcr/model/arch/gp_mean_fpv4.hpp"
#include "cdcr/model/arch/portable.hpp"
#include "cdcr/model/compensated_float.hpp"
#include "cdcr/model/work_costs.hpp"

namespace cdcr::model::arch {

struct Fpv4 : Portable {
  static constexpr bool kBlockLoads = true;

  // Measured on the Cortex-M4F (qemu.cycle_budget_m4f prints the figures):
  // a mean point 54 instructions (the assembly loop), with the gradient 149;
  // the IK Jacobian at most 20,500, the damped step 20,700, the outer step
  // 8,100 (the IK code is built at -O2, firmware/CMakeLists.txt); a
  // request's end about 10,000 (the setpoint frames 7,800, scaled in single
  // precision where that gives the double result; the report 1,100); the
  // rest of a cycle at most about 15,000 beyond the units spent, with a
  // target's start and a superseded report. 2,130 units are 115,000
  // instructions, within the board's 120,000; at the full 1,024 training
  // points they leave the IK 806 units a cycle, more than its costliest step.
  // A payload model's point (9 inputs, the run-time loop): 3 and 10 units.
  // A drive behind Hal::drives (CiA 402) measured 797 instructions a cycle
  // (qemu.cia402_budget_m4f: 12,751 for 16 drives; the conversions between
  // counts and mm are doubles, in software here): 15 units.
  static constexpr WorkCosts kWorkCosts{3, {380, 385, 150}, 185, 300, 2130, 3, 10, 15};

#define CDCR_VLDM_OUT(i) "=t"(r##i)
  template <int Count>
  static void load_block(const float*& from, float (&to)[Count]) {
    static_assert(Count == 4 || Count == 6 || Count == 8, "block loads of 4, 6 or 8 floats");
    register float r0 asm("s16");
    register float r1 asm("s17");
    register float r2 asm("s18");
    register float r3 asm("s19");
    register float r4 asm("s20");
    register float r5 asm("s21");
    register float r6 asm("s22");
    register float r7 asm("s23");
    if constexpr (Count == 4) {
      asm("vldmia %[p]!, {s16-s19}"
          : CDCR_VLDM_OUT(0), CDCR_VLDM_OUT(1), CDCR_VLDM_OUT(2), CDCR_VLDM_OUT(3), [p] "+r"(from)
          : "m"(*reinterpret_cast<const float(*)[4]>(from)));
    } else if constexpr (Count == 6) {
      asm("vldmia %[p]!, {s16-s21}"
          : CDCR_VLDM_OUT(0), CDCR_VLDM_OUT(1), CDCR_VLDM_OUT(2), CDCR_VLDM_OUT(3), CDCR_VLDM_OUT(4),
            CDCR_VLDM_OUT(5), [p] "+r"(from)
          : "m"(*reinterpret_cast<const float(*)[6]>(from)));
    } else {
      asm("vldmia %[p]!, {s16-s23}"
          : CDCR_VLDM_OUT(0), CDCR_VLDM_OUT(1), CDCR_VLDM_OUT(2), CDCR_VLDM_OUT(3), CDCR_VLDM_OUT(4),
            CDCR_VLDM_OUT(5), CDCR_VLDM_OUT(6), CDCR_VLDM_OUT(7), [p] "+r"(from)
          : "m"(*reinterpret_cast<const float(*)[8]>(from)));
    }
    const float loaded[8] = {r0, r1, r2, r3, r4, r5, r6, r7};
#pragma GCC unroll 16
    for (int i = 0; i < Count; ++i) to[i] = loaded[i];
  }
#undef CDCR_VLDM_OUT

  template <int Dims, typename S, typename Accumulator, std::uint32_t BlockPoints>
  static constexpr bool has_mean_blocks() {
    return Dims == 8 && std::is_same_v<S, float> && std::is_same_v<Accumulator, CompensatedFloat> &&
           BlockPoints == detail::kFpv4BlockPoints;
  }

  // `blocks` (at least 1) full blocks; advances inputs and alpha past them.
  static void mean_blocks(const float* query, const float*& inputs, const float*& alpha, std::uint32_t blocks,
                          CompensatedFloat* sums) {
    detail::gp_mean_blocks_fpv4(query, inputs, alpha, blocks, sums);
  }
};

}  // namespace cdcr::model::arch
