#pragma once
// One cable-driven segment (Section III-A): its cables (the paper's four,
// or three; geometry.hpp's CableLayout) -> (alpha, theta) -> pose of the
// moving platform in the segment's base frame.
//
// Two coordinates describe the same bend:
//   * the paper's joint variables (alpha, theta): bending-plane angle and
//     bending angle. alpha is undefined at theta = 0 and wraps at +-pi;
//   * the bend vector b = theta * (cos alpha, sin alpha), which is smooth
//     everywhere. The segment pose is an analytic function of b, so the
//     kinematics and Jacobians below are evaluated in b and never divide by
//     theta.

#include <algorithm>
#include <cmath>
#include <limits>

#include "cdcr/model/geometry.hpp"
#include "cdcr/model/se3.hpp"
#include "cdcr/model/series.hpp"
#include "cdcr/model/status.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model {

template <typename S>
struct SegmentJoints {
  S alpha_rad = S(0);  // rotation of the bending plane about z, in [-pi, pi]
  S theta_rad = S(0);  // bending angle, in [0, theta_max]
};

template <typename S>
Vec2<S> bend_from_joints(const SegmentJoints<S>& q) {
  return Vec2<S>(q.theta_rad * std::cos(q.alpha_rad), q.theta_rad * std::sin(q.alpha_rad));
}

// alpha is reported as 0 for a straight segment, where any value is correct.
template <typename S>
SegmentJoints<S> joints_from_bend(const Vec2<S>& b) {
  return SegmentJoints<S>{std::atan2(b.y(), b.x()), b.norm()};
}

// What the least-squares fit of eq. (2) reads of a segment's cables
// (geometry.hpp's CableLayout): the mean m and the chord vector D, for the
// paper's four cables (l3 - l1, l2 - l4), and D's length. `status` is not ok
// for impossible lengths (or geometry, or a cable count other than the
// layout's); nothing is computed then.
template <typename S>
struct CableDifferences {
  Status status = Status::ok;
  S mean = S(0);
  S d31 = S(0), d24 = S(0), chord = S(0), reach = S(0);  // D = (d31, d24); reach = 4 r, the largest chord
};

// sum_j w_j l_j over the layout's cables, in cable order (with the paper's
// weights, 0, +-1 and 1/4, every product is exact and the sums are those of
// eqs. (3)-(5)).
template <typename S, typename Derived>
S layout_sum(const std::array<S, kMaxCablesPerSegment>& weights, const Eigen::MatrixBase<Derived>& cables_mm,
             int count) {
  S sum = weights[0] * cables_mm[0];
  for (int j = 1; j < count; ++j) sum += weights[j] * cables_mm[j];
  return sum;
}

template <typename S, typename Derived>
CableDifferences<S> cable_differences(const Eigen::MatrixBase<Derived>& cables_mm,
                                      const SegmentGeometry<S>& geometry) {
  CableDifferences<S> d;
  const CableLayout<S>& layout = geometry.cables;
  // Cable by cable: Eigen's reductions over a vector of at most four read
  // packets GCC takes for reads past its end.
  bool finite = true;
  bool positive = true;
  for (Eigen::Index j = 0; j < cables_mm.size(); ++j) {
    finite = finite && std::isfinite(cables_mm[j]);
    positive = positive && cables_mm[j] > S(0);
  }
  if (const Status s = geometry.validate(); s != Status::ok) {
    d.status = s;
  } else if (cables_mm.size() != layout.count) {
    d.status = Status::invalid_segment_count;
  } else if (!finite) {
    d.status = Status::non_finite_input;
  } else if (!positive) {
    d.status = Status::cable_length_not_positive;
  } else {
    d.mean = layout_sum(layout.mean_weights, cables_mm, layout.count);
    d.d31 = layout_sum(layout.chord_x_weights, cables_mm, layout.count);
    d.d24 = layout_sum(layout.chord_y_weights, cables_mm, layout.count);
    d.reach = S(4) * geometry.anchor_radius_mm;
    d.chord = std::hypot(d.d31, d.d24);
  }
  return d;
}

// Eqs. (2)-(5). alpha = atan2(l2 - l4, l3 - l1): eq. (4) as printed has the
// opposite sign and loses the quadrant; this form reproduces Table 1. Any
// layout: alpha = atan2(D_y, D_x), theta = 2 asin(|D| / 4r).
// cable_resolution_mm: the step of the measured lengths (the drives report
// in steps of the protocol's scale). A segment at its limit reads up to one
// step of each cable difference beyond it; that is still the limit.
template <typename S, typename Derived>
Status joints_from_cables(const Eigen::MatrixBase<Derived>& cables_mm, const SegmentGeometry<S>& geometry,
                          SegmentJoints<S>& joints, S cable_resolution_mm = S(0)) {
  const CableDifferences<S> d = cable_differences(cables_mm, geometry);
  if (d.status != Status::ok) return d.status;
  const S reach = d.reach;
  const S chord = d.chord;
  if (chord > reach) return Status::cable_difference_out_of_range;
  const S theta = S(2) * std::asin(chord / reach);
  // Cables that cables_from_joints computed at theta = theta_max read back up
  // to about eps * l / r above the limit (one rounding of each cable length,
  // divided by the lever arm). That is the limit itself, not beyond it.
  const S rounding_rad = S(16) * std::numeric_limits<S>::epsilon() * cables_mm.maxCoeff() / geometry.anchor_radius_mm;
  if (theta > geometry.theta_max_rad + rounding_rad) {
    // Both differences may be off by one step: the chord by up to sqrt(2)
    // steps. Only cables past the limit pay for the second arcsine.
    const S chord_within_resolution = std::max(S(0), chord - S(1.41421356) * cable_resolution_mm);
    if (S(2) * std::asin(chord_within_resolution / reach) > geometry.theta_max_rad + rounding_rad) {
      return Status::theta_beyond_limit;
    }
  }
  joints = SegmentJoints<S>{std::atan2(d.d24, d.d31), std::min(theta, geometry.theta_max_rad)};
  return Status::ok;
}

template <typename S>
Status check_joints(const SegmentJoints<S>& joints, const SegmentGeometry<S>& geometry) {
  if (const Status s = geometry.validate(); s != Status::ok) return s;
  if (!std::isfinite(joints.alpha_rad) || !std::isfinite(joints.theta_rad)) return Status::non_finite_input;
  if (joints.theta_rad < S(0) || joints.theta_rad > geometry.theta_max_rad) return Status::theta_beyond_limit;
  return Status::ok;
}

// Eq. (2): l_j = 2 (L/theta) sin(theta/2) - 2 r cos(alpha + (j-1) pi/2) sin(theta/2).
// With s = sin(theta/2)/(theta/2), b = (u, w) and the anchors' directions
// e_j this is l_j = L s - r s (b . e_j): for the paper's four cables
//   l = L s + r s * (-u, +w, +u, -w).
template <typename S>
Status cables_from_joints(const SegmentJoints<S>& joints, const SegmentGeometry<S>& geometry,
                          SegmentCables<S>& cables_mm) {
  if (const Status s = check_joints(joints, geometry); s != Status::ok) return s;
  const Vec2<S> b = bend_from_joints(joints);
  const S s = series::sinc(joints.theta_rad / S(2));
  const S mean = geometry.backbone_length_mm * s;
  const S r = geometry.anchor_radius_mm * s;
  const CableLayout<S>& layout = geometry.cables;
  SegmentCables<S> cables(layout.count);
  // Checked cable by cable (a NaN fails too): Eigen's minCoeff over a
  // vector of at most four reads packets GCC takes for reads past its end.
  bool positive = true;
  for (int j = 0; j < layout.count; ++j) {
    cables[j] = mean - r * (b.x() * layout.anchor_x[j] + b.y() * layout.anchor_y[j]);
    positive = positive && cables[j] > S(0);
  }
  if (!positive) return Status::cable_length_not_positive;
  cables_mm = cables;
  return Status::ok;
}

// The same for a layout of four cables, into a fixed four-vector.
template <typename S>
Status cables_from_joints(const SegmentJoints<S>& joints, const SegmentGeometry<S>& geometry, Vec4<S>& cables_mm) {
  if (geometry.cables.count != 4) return Status::invalid_segment_count;
  SegmentCables<S> cables;
  const Status s = cables_from_joints(joints, geometry, cables);
  if (s == Status::ok) cables_mm = cables;
  return s;
}

// Pose of the moving platform in the segment base frame, as the
// constant-curvature arc that the POE formula (6)-(12) reduces to:
//   R = Rot(omega, theta), omega = (-sin alpha, cos alpha, 0)
//   p = (L/theta) ((1 - cos theta) cos alpha, (1 - cos theta) sin alpha, sin theta)
// In the bend vector, with k = theta * omega = (-w, u, 0):
//   R = I + A hat(k) + B hat(k)^2,  p = L (B u, B w, A)
// where A = sin(theta)/theta and B = (1 - cos theta)/theta^2. Exact at theta = 0.
template <typename S>
Pose<S> segment_pose(const Vec2<S>& bend, S backbone_length_mm) {
  const S u = bend.x();
  const S w = bend.y();
  const S theta = bend.norm();
  const S a = series::sinc(theta);
  const S b = series::one_minus_cos_over_sq(theta);
  const Mat3<S> K = hat3<S>(Vec3<S>(-w, u, S(0)));
  Pose<S> pose;
  pose.rotation = Mat3<S>::Identity() + a * K + b * (K * K);
  pose.position_mm = backbone_length_mm * Vec3<S>(b * u, b * w, a);
  return pose;
}

// T_{i-1,i}(0) of eq. (7): the straight segment.
template <typename S>
Pose<S> segment_initial_pose(S backbone_length_mm) {
  Pose<S> pose;
  pose.position_mm = Vec3<S>(S(0), S(0), backbone_length_mm);
  return pose;
}

// The screw axis xi = (v, omega) of eqs. (6), (11), (12) such that
// T(alpha, theta) = exp(hat(xi) theta) T(0). Derived by equating (9) and (10):
// the motion has zero pitch about an axis through the point
// q = ((L/theta - (L/2) cot(theta/2)) (cos alpha, sin alpha), L/2), so
//   omega = (-sin alpha, cos alpha, 0)
//   v = q x omega = L (-cos(alpha)/2, -sin(alpha)/2, 1/theta - cot(theta/2)/2).
// The last entry tends to theta/12 at theta -> 0, so the axis stays finite.
template <typename S>
Twist<S> segment_screw_axis(const SegmentJoints<S>& joints, S backbone_length_mm) {
  const S ca = std::cos(joints.alpha_rad);
  const S sa = std::sin(joints.alpha_rad);
  const S t = joints.theta_rad;
  // 1/theta - cot(theta/2)/2 = theta * log_translation_coefficient(theta)
  const S axial = t * series::log_translation_coefficient(t);
  Twist<S> xi;
  xi.template head<3>() = backbone_length_mm * Vec3<S>(-ca / S(2), -sa / S(2), axial);
  xi.template tail<3>() = Vec3<S>(-sa, ca, S(0));
  return xi;
}

// Spatial twists (in the segment base frame) of d/du and d/dw of the segment
// pose: hat(col_k) = (dT/db_k) T^-1. Derived from the closed form above;
// with C = (theta - sin theta)/theta^3:
//   d/du: v = L (-B, 0, C u),  omega = (-C u w, 1 - C w^2, -B w)
//   d/dw: v = L (0, -B, C w),  omega = (-(1 - C u^2), C u w, B u)
template <typename S>
Eigen::Matrix<S, 6, 2> segment_bend_twists(const Vec2<S>& bend, S backbone_length_mm) {
  const S u = bend.x();
  const S w = bend.y();
  const S theta = bend.norm();
  const S b = series::one_minus_cos_over_sq(theta);
  const S c = series::x_minus_sin_over_cube(theta);
  const S L = backbone_length_mm;
  Eigen::Matrix<S, 6, 2> twists;
  twists.col(0) << -L * b, S(0), L * c * u, -c * u * w, S(1) - c * w * w, -b * w;
  twists.col(1) << S(0), -L * b, L * c * w, -(S(1) - c * u * u), c * u * w, b * u;
  return twists;
}

// The same for the paper's joint variables (d/dalpha, d/dtheta):
//   d/dtheta: v = L (-B cos alpha, -B sin alpha, theta C), omega = (-sin alpha, cos alpha, 0)
//   d/dalpha: v = L theta B (sin alpha, -cos alpha, 0),
//             omega = (-A theta cos alpha, -A theta sin alpha, theta^2 B)
// d/dalpha vanishes at theta = 0, where alpha has no effect.
template <typename S>
Eigen::Matrix<S, 6, 2> segment_joint_twists(const SegmentJoints<S>& joints, S backbone_length_mm) {
  const S ca = std::cos(joints.alpha_rad);
  const S sa = std::sin(joints.alpha_rad);
  const S t = joints.theta_rad;
  const S a = series::sinc(t);
  const S b = series::one_minus_cos_over_sq(t);
  const S c = series::x_minus_sin_over_cube(t);
  const S L = backbone_length_mm;
  Eigen::Matrix<S, 6, 2> twists;
  twists.col(0) << L * t * b * sa, -L * t * b * ca, S(0), -a * t * ca, -a * t * sa, t * t * b;
  twists.col(1) << -L * b * ca, -L * b * sa, L * t * c, -sa, ca, S(0);
  return twists;
}

}  // namespace cdcr::model
