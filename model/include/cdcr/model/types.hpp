#pragma once
// Eigen aliases used across the model. Only fixed-size types, or fixed-capacity
// ones (Dynamic with a compile-time maximum, stored inline) — never heap-backed.

#include <Eigen/Core>

#include "cdcr/model/limits.hpp"

namespace cdcr::model {

template <typename S> using Vec2 = Eigen::Matrix<S, 2, 1>;
template <typename S> using Vec3 = Eigen::Matrix<S, 3, 1>;
template <typename S> using Vec4 = Eigen::Matrix<S, 4, 1>;
template <typename S> using Mat3 = Eigen::Matrix<S, 3, 3>;
template <typename S> using Mat4 = Eigen::Matrix<S, 4, 4>;
template <typename S> using Mat6 = Eigen::Matrix<S, 6, 6>;

// A twist in se(3), ordered (v, omega): linear part first, angular part second,
// as in the paper's xi = (v, omega). Every file format and API uses this order.
template <typename S> using Twist = Eigen::Matrix<S, 6, 1>;

// Per-segment quantities stacked segment by segment: [a_1, b_1, a_2, b_2, ...].
template <typename S, int MaxSegments = kMaxSegments>
using JointVector = Eigen::Matrix<S, Eigen::Dynamic, 1, Eigen::ColMajor, 2 * MaxSegments, 1>;

// Cable lengths stacked segment by segment, [l1_1, l1_2, l1_3, l1_4, l2_1,
// ...] in mm for the paper's four cables a segment (geometry.hpp's
// RobotGeometry::first_cable() says where a segment's cables start).
template <typename S, int MaxSegments = kMaxSegments>
using CableVector = Eigen::Matrix<S, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxCablesPerSegment * MaxSegments, 1>;

// One segment's cable lengths, 3 or 4 (mm).
template <typename S>
using SegmentCables = Eigen::Matrix<S, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxCablesPerSegment, 1>;

// d(twist)/d(joints): 6 rows, two columns per segment.
template <typename S, int MaxSegments = kMaxSegments>
using Jacobian = Eigen::Matrix<S, 6, Eigen::Dynamic, Eigen::ColMajor, 6, 2 * MaxSegments>;

}  // namespace cdcr::model
