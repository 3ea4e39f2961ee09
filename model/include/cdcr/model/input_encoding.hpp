#pragma once
// How joint variables become the GP input vector x (one pair per segment).
//
// * joint_angles: the paper's eq. (17), x = [alpha_1, theta_1, ...]. It jumps
//   where alpha wraps at +-pi, and alpha is arbitrary at theta = 0, so
//   configurations that are physically close can be far apart in x.
// * bend_vector: x = [theta_1 cos alpha_1, theta_1 sin alpha_1, ...], smooth
//   and single-valued everywhere.

#include <cmath>
#include <cstdint>

#include "cdcr/model/chain.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model {

enum class InputEncoding : std::uint8_t {
  joint_angles = 1,
  bend_vector = 2,
};

constexpr const char* to_string(InputEncoding encoding) {
  switch (encoding) {
    case InputEncoding::joint_angles: return "joint-angles";
    case InputEncoding::bend_vector: return "bend-vector";
  }
  return "unknown";
}

constexpr bool is_known(InputEncoding encoding) {
  return encoding == InputEncoding::joint_angles || encoding == InputEncoding::bend_vector;
}

// x from the stacked bend vector.
template <typename Derived, typename Out>
void encode_inputs(InputEncoding encoding, const Eigen::MatrixBase<Derived>& bend, Eigen::MatrixBase<Out>& x) {
  if (encoding == InputEncoding::bend_vector) {
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
  if (encoding == InputEncoding::bend_vector) return Eigen::Matrix<S, 2, 2>::Identity();
  const S theta_sq = std::max(bend.squaredNorm(), S(1e-12));
  const S theta = std::sqrt(theta_sq);
  Eigen::Matrix<S, 2, 2> block;
  block << -bend.y() / theta_sq, bend.x() / theta_sq,  // d alpha / d(u, w)
      bend.x() / theta, bend.y() / theta;              // d theta / d(u, w)
  return block;
}

}  // namespace cdcr::model
