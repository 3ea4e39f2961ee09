#pragma once
// GpCorrection's loops on a Cortex-M7 with the double-precision FPU (FPv5):
// FPv4's block loads, and the mean's loop for 8 inputs (4 segments) with
// float terms and double sums in assembly (gp_mean_fpv5.hpp).

#include <cstdint>
#include <type_traits>

#include "cdcr/model/arch/fpv4.hpp"
#include "cdcr/model/arch/gp_mean_fpv5.hpp"

namespace cdcr::model::arch {

struct Fpv5 : Fpv4 {
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
