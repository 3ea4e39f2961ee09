#pragma once
// GpCorrection's loops on a Cortex-M7 with the double-precision FPU (FPv5):
// FPv4's block loads, and the mean's loop for 8 inputs (4 segments) with
// float terms and double sums in assembly (gp_mean_fpv5.hpp).

#include <cstdint>
#include <type_traits>

#include "cdcr/model/arch/fpv4.hpp"
#include "cdcr/model/arch/gp_mean_fpv5.hpp"
#include "cdcr/model/work_costs.hpp"

namespace cdcr::model::arch {

struct Fpv5 : Fpv4 {
  // Measured on the Cortex-M7 (qemu.cycle_budget_m7 prints the figures): a
  // mean point 47 instructions, with the gradient 142; the IK Jacobian at
  // most 13,000, the damped step 16,300, the outer step 5,500 (each charged
  // a little above); a request's end 3,700; the rest of a cycle at most
  // about 7,800 beyond the units spent. 1,700 units are 79,900 instructions
  // at 47 a unit; with the charges' margins the workload's worst cycle is
  // 76,800 with the demo's model and 76,000 at the full 1,024 points, within
  // the board's 80,000.
  // A payload model's point (9 inputs, the run-time loop) measured 100
  // instructions, with its gradient 418 (473 points): 3 and 10 units.
  // The cycle's rest is charged 230 units since three cables a segment
  // (every read-out of the cables through the segment's layout): at 200
  // the workload's worst cycle reached 80,096 with the demo's model as a
  // fresh build trains it; at 230 it is 79,802 (IK 578 units a cycle).
  // 260 since CAN FD's 64-byte frames and the second bus (every frame
  // built, queued and taken is 72 bytes, and a cycle receives from two
  // buses): at 230 the workload's worst cycle reached 81,245.
  // A drive behind Hal::drives (CiA 402) measured 356 instructions a cycle
  // (qemu.cia402_budget_m7: 5,689 for 16 drives): 8 units.
  static constexpr WorkCosts kWorkCosts{3, {290, 390, 135}, 140, 260, 1700, 3, 10, 8};

  template <int Dims, typename S, typename Accumulator, std::uint32_t BlockPoints>
  static constexpr bool has_mean_blocks() {
    return Dims == 8 && std::is_same_v<S, float> && std::is_same_v<Accumulator, double> &&
           BlockPoints == detail::kFpv5BlockPoints;
  }

  // `blocks` (at least 1) full blocks; advances inputs and alpha past them.
  static void mean_blocks(const float* query, const float*& inputs, const float*& alpha, std::uint32_t blocks,
                          double* sums) {
    detail::gp_mean_blocks_fpv5(query, inputs, alpha, blocks, sums);
  }
};

}  // namespace cdcr::model::arch
