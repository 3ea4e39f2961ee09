#pragma once
// Every fallible function in the model library reports through Status rather
// than exceptions or NaN results, so the same code can run on a motor
// controller with -fno-exceptions and on the training PC.

#include <cstdint>

namespace cdcr::model {

enum class Status : std::uint8_t {
  ok = 0,
  non_finite_input,        // NaN or Inf in any argument
  invalid_geometry,        // backbone length, anchor radius or theta limit not positive
  cable_length_not_positive,
  cable_difference_out_of_range,  // |l3-l1| or |l4-l2| (or their hypot) beyond 4r: outside asin
  theta_beyond_limit,      // bending angle outside [0, theta_max]
  invalid_segment_count,   // zero segments, more than the compile-time capacity, or a size mismatch
  ik_not_converged,        // iteration budget spent before reaching the tolerance
  correction_failed,       // the optional IK correction term reported a failure
};

constexpr const char* to_string(Status status) {
  switch (status) {
    case Status::ok: return "ok";
    case Status::non_finite_input: return "input contains NaN or Inf";
    case Status::invalid_geometry: return "geometry must be positive (backbone length, anchor radius, theta limit)";
    case Status::cable_length_not_positive: return "cable length must be positive";
    case Status::cable_difference_out_of_range: return "cable length difference exceeds 4 x anchor radius (no bending angle reaches it)";
    case Status::theta_beyond_limit: return "bending angle theta is beyond the segment limit";
    case Status::invalid_segment_count: return "segment count is zero, above capacity, or does not match the input";
    case Status::ik_not_converged: return "inverse kinematics did not converge";
    case Status::correction_failed: return "kinematic correction term failed";
  }
  return "unknown status";
}

}  // namespace cdcr::model
