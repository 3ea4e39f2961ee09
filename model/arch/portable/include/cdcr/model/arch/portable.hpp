#pragma once
// The architecture hooks of GpCorrection's loops in plain C++: the reference
// the other architectures (model/arch/fpv4, model/arch/fpv5) must match bit
// for bit, and what every host build runs. An architecture may replace
//   - load_block: a training point's floats (or its alphas) into registers;
//   - mean_blocks: the mean's whole loop over full blocks of training points,
//     for the configurations has_mean_blocks() names;
//   - mean_range and mean_and_gradient_range: the whole loops over a range of
//     points, for the types has_vector_loops() names, on a CPU where
//     vector_loops_available();
//   - multiply_add and gaussian: the arithmetic of a point in the C++ loops.
// Here there is no hand-written loop, so GpCorrection's own C++ loop runs:
// that loop is the reference, with kernel_exp.hpp's arithmetic for the core
// it is built for (fused and polynomial on a Cortex-M FPU).

#include <cstdint>

#include "cdcr/model/kernel_exp.hpp"
#include "cdcr/model/work_costs.hpp"

namespace cdcr::model::arch {

struct Portable {
  // A host core: the costs only steer how IK work is spread over cycles (a
  // host has no instruction budget), so round figures of the Cortex-M kind.
  static constexpr WorkCosts kWorkCosts{3, {300, 400, 120}, 150, 150, 2000};

  // Whether load_block is worth calling: the loops read the floats one by
  // one where it is not.
  static constexpr bool kBlockLoads = false;

  template <int Count>
  static void load_block(const float*& from, float (&to)[Count]) {
    for (int i = 0; i < Count; ++i) to[i] = from[i];
    from += Count;
  }

  template <int Dims, typename S, typename Accumulator, std::uint32_t BlockPoints>
  static constexpr bool has_mean_blocks() {
    return false;
  }

  // Only where this is true are the other three hooks called.
  template <typename S, typename Accumulator>
  static constexpr bool has_vector_loops() {
    return false;
  }

  template <typename S>
  static S multiply_add(S a, S b, S c) {
    return model::multiply_add(a, b, c);
  }
  template <typename S>
  static S gaussian(S distance_sq) {
    return model::gaussian(distance_sq);
  }
};

}  // namespace cdcr::model::arch
