#pragma once

// The one rule for the quaternions the project reads and writes: CAN
// frames, the C API, dataset rows and the command line. They are Hamilton,
// w first. A quaternion read must have a norm within kQuaternionNormTolerance
// of 1 and is normalised after the check: a norm further off is a mistake,
// not rounding (Q15 in a frame moves the norm by at most ~1e-4, six printed
// decimals by ~1e-6). A quaternion written has w >= 0, so that each
// rotation has one encoding.

#include <cmath>

#include <Eigen/Geometry>

#include "cdcr/model/types.hpp"

namespace cdcr::model {

inline constexpr double kQuaternionNormTolerance = 1e-3;

// False for a norm that is NaN or infinite.
inline bool is_unit_quaternion_norm(double norm) { return std::abs(norm - 1.0) <= kQuaternionNormTolerance; }

// The same rotation with w >= 0.
template <typename S>
Eigen::Quaternion<S> with_positive_w(Eigen::Quaternion<S> quaternion) {
  if (quaternion.w() < S(0)) quaternion.coeffs() = -quaternion.coeffs();
  return quaternion;
}

// The unit quaternion of a rotation matrix, with w >= 0.
template <typename S>
Eigen::Quaternion<S> canonical_quaternion(const Mat3<S>& rotation) {
  Eigen::Quaternion<S> quaternion(rotation);
  quaternion.normalize();
  return with_positive_w(quaternion);
}

}  // namespace cdcr::model
