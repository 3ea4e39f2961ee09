#pragma once
// How joint variables become the GP input vector x (one pair per segment).
//
// * joint_angles: the paper's eq. (17), x = [alpha_1, theta_1, ...]. It jumps
//   where alpha wraps at +-pi, and alpha is arbitrary at theta = 0, so
//   configurations that are physically close can be far apart in x.
// * bend_vector: x = [theta_1 cos alpha_1, theta_1 sin alpha_1, ...], smooth
//   and single-valued everywhere.
// * bend_vector_cable_fit: the bend vector, then per segment what its cables
//   say beyond the bend, the cable fit's common mode and pair imbalance
//   (cable_fit.hpp), [rho_1, pi_1, rho_2, pi_2, ...] in mm. The bend is the
//   variable (IK's); the residuals are state measured from the cables, held
//   like the payload.
// * bend_vector_history, bend_vector_cable_fit_history: either of the two,
//   then per segment where each of its cables last moved, [h_1_1 .. h_1_4,
//   h_2_1, ...] in [-1, 1] (hysteresis.hpp, history_inputs): state of the
//   cables' friction, which the hysteresis block's last operator keeps.

#include <cmath>
#include <cstdint>

#include "cdcr/model/chain.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model {

enum class InputEncoding : std::uint8_t {
  joint_angles = 1,
  bend_vector = 2,
  bend_vector_cable_fit = 3,
  bend_vector_history = 4,
  bend_vector_cable_fit_history = 5,
};

constexpr const char* to_string(InputEncoding encoding) {
  switch (encoding) {
    case InputEncoding::joint_angles: return "joint-angles";
    case InputEncoding::bend_vector: return "bend-vector";
    case InputEncoding::bend_vector_cable_fit: return "bend-vector+cable-fit";
    case InputEncoding::bend_vector_history: return "bend-vector+history";
    case InputEncoding::bend_vector_cable_fit_history: return "bend-vector+cable-fit+history";
  }
  return "unknown";
}

constexpr bool is_known(InputEncoding encoding) {
  return encoding == InputEncoding::joint_angles || encoding == InputEncoding::bend_vector ||
         encoding == InputEncoding::bend_vector_cable_fit || encoding == InputEncoding::bend_vector_history ||
         encoding == InputEncoding::bend_vector_cable_fit_history;
}

constexpr bool takes_cable_residuals(InputEncoding encoding) {
  return encoding == InputEncoding::bend_vector_cable_fit || encoding == InputEncoding::bend_vector_cable_fit_history;
}

constexpr bool takes_history(InputEncoding encoding) {
  return encoding == InputEncoding::bend_vector_history || encoding == InputEncoding::bend_vector_cable_fit_history;
}

// The encoding that adds (or drops) the history inputs, the rest the same;
// joint angles take none.
constexpr InputEncoding with_history(InputEncoding encoding, bool history) {
  if (encoding == InputEncoding::joint_angles) return encoding;
  if (takes_cable_residuals(encoding)) {
    return history ? InputEncoding::bend_vector_cable_fit_history : InputEncoding::bend_vector_cable_fit;
  }
  return history ? InputEncoding::bend_vector_history : InputEncoding::bend_vector;
}

// Inputs of what a segment's cables say beyond the bend (cable_fit.hpp):
// the common mode, and with four cables the pairs' imbalance.
constexpr int cable_residual_inputs(int cables) { return cables - 2; }

// Inputs the encoding gives a segment of `cables` cables: its bend, its
// residuals, where each of its cables last moved.
constexpr int encoded_segment_inputs(InputEncoding encoding, int cables) {
  return 2 + (takes_cable_residuals(encoding) ? cable_residual_inputs(cables) : 0) +
         (takes_history(encoding) ? cables : 0);
}

// Inputs the encoding gives a robot of `segments` segments of the paper's
// four cables (before any extra input).
constexpr int encoded_input_count(InputEncoding encoding, int segments) {
  return encoded_segment_inputs(encoding, 4) * segments;
}

// ... and of any geometry's cables.
template <typename S, int Max>
int encoded_input_count(InputEncoding encoding, const RobotGeometry<S, Max>& geometry) {
  int inputs = 0;
  for (int i = 0; i < geometry.segment_count; ++i) inputs += encoded_segment_inputs(encoding, geometry.segments[i].cables.count);
  return inputs;
}

// The bend's part of x (its first 2n values) from the stacked bend vector.
template <typename Derived, typename Out>
void encode_inputs(InputEncoding encoding, const Eigen::MatrixBase<Derived>& bend, Eigen::MatrixBase<Out>& x) {
  if (encoding != InputEncoding::joint_angles) {
    x = bend;
  } else {
    x = joints_from_bend(bend);
  }
}

// dx/d(bend) is block diagonal; returns the 2x2 block of segment i. For
// joint_angles it is singular at theta = 0, where alpha has no derivative;
// there the block is evaluated at a tiny theta so it stays finite.
template <typename S>
Eigen::Matrix<S, 2, 2> encoding_jacobian_block(InputEncoding encoding, const Vec2<S>& bend) {
  if (encoding != InputEncoding::joint_angles) return Eigen::Matrix<S, 2, 2>::Identity();
  const S theta_sq = std::max(bend.squaredNorm(), S(1e-12));
  const S theta = std::sqrt(theta_sq);
  Eigen::Matrix<S, 2, 2> block;
  block << -bend.y() / theta_sq, bend.x() / theta_sq,  // d alpha / d(u, w)
      bend.x() / theta, bend.y() / theta;              // d theta / d(u, w)
  return block;
}

}  // namespace cdcr::model
