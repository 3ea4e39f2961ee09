#pragma once
// A float accumulator that carries its own rounding error, for the GP mean's
// sums on cores without a double-precision FPU (the Cortex-M4F).
//
// Each addition keeps the exact error of sum + term, found by Knuth's
// TwoSum: six additions and no branch. Neumaier's variant (the same error,
// from Fast2Sum on the operands ordered by magnitude) needs a compare and a
// branch per term; in round-to-nearest both give the error exactly, so both
// give the same bits. The Cortex-M4F's assembly mean loop
// (model/arch/fpv4/.../gp_mean_fpv4.hpp) performs these operations in this
// order.

namespace cdcr::model {

struct CompensatedFloat {
  float sum = 0.0f;
  float compensation = 0.0f;

  CompensatedFloat& operator+=(float term) {
    const float t = sum + term;
    const float term_part = t - sum;
    compensation += (sum - (t - term_part)) + (term - term_part);
    sum = t;
    return *this;
  }
  float value() const { return sum + compensation; }
};

}  // namespace cdcr::model
