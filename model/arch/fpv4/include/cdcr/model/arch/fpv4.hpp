#pragma once
// GpCorrection's loops on a Cortex-M with a single-precision FPU (FPv4-SP,
// the Cortex-M4F; FPv5 builds on it): the portable loops, with block loads.
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

#include "cdcr/model/arch/portable.hpp"
#include "cdcr/model/work_costs.hpp"

namespace cdcr::model::arch {

struct Fpv4 : Portable {
  static constexpr bool kBlockLoads = true;

  // Measured on the Cortex-M4F (qemu.cycle_budget_m4f prints the figures):
  // a mean point 72 instructions in the forward path and 82 in the IK's
  // slices, with the gradient 148; the IK Jacobian at most 20,400, the
  // damped step 20,600, the outer step 7,800 (the IK code is built at -O2,
  // firmware/CMakeLists.txt); a request's end about 10,000 (the setpoint
  // frames 7,800, scaled in single precision where that gives the double
  // result; the report 1,100); the rest of a cycle at most about 15,000
  // beyond the units spent, with a target's start and a superseded report,
  // and the IK slices' dearer mean points. The overhead's 325 units leave
  // the IK 575 a cycle with the demo's 700 points: a Jacobian and a damped
  // step in one cycle. 1,600 units are 115,200 instructions; the workload's
  // worst cycle is 119,000, within the board's 120,000.
  static constexpr WorkCosts kWorkCosts{3, {285, 290, 110}, 150, 325, 1600};

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
};

}  // namespace cdcr::model::arch
