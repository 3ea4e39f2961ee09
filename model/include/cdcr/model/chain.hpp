#pragma once
// The robot: n segments in series (eq. 13), T_0n = T_01 T_12 ... T_(n-1)n,
// with no extra transform between segments. n is a run-time value up to the
// geometry's compile-time capacity.
//
// Joint vectors stack the paper's variables per segment, [alpha_1, theta_1,
// alpha_2, theta_2, ...]; bend vectors stack b_i = theta_i (cos alpha_i,
// sin alpha_i) the same way.

#include "cdcr/model/geometry.hpp"
#include "cdcr/model/se3.hpp"
#include "cdcr/model/segment.hpp"
#include "cdcr/model/status.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model {

template <typename Derived>
SegmentJoints<typename Derived::Scalar> segment_joints(const Eigen::MatrixBase<Derived>& joints, int i) {
  return SegmentJoints<typename Derived::Scalar>{joints[2 * i], joints[2 * i + 1]};
}

template <typename S, int Max>
Status joints_from_cables(const CableVector<S, Max>& cables_mm, const RobotGeometry<S, Max>& geometry,
                          JointVector<S, Max>& joints, S cable_resolution_mm = S(0)) {
  if (const Status s = geometry.validate(); s != Status::ok) return s;
  if (cables_mm.size() != geometry.cable_count()) return Status::invalid_segment_count;
  JointVector<S, Max> result(2 * geometry.segment_count);
  for (int i = 0, first = 0; i < geometry.segment_count; first += geometry.segments[i].cables.count, ++i) {
    SegmentJoints<S> q;
    const auto segment_cables = cables_mm.segment(first, geometry.segments[i].cables.count);
    if (const Status s = joints_from_cables(segment_cables, geometry.segments[i], q, cable_resolution_mm);
        s != Status::ok) {
      return s;
    }
    result[2 * i] = q.alpha_rad;
    result[2 * i + 1] = q.theta_rad;
  }
  joints = result;
  return Status::ok;
}

template <typename S, int Max>
Status check_joints(const JointVector<S, Max>& joints, const RobotGeometry<S, Max>& geometry) {
  if (const Status s = geometry.validate(); s != Status::ok) return s;
  if (joints.size() != 2 * geometry.segment_count) return Status::invalid_segment_count;
  for (int i = 0; i < geometry.segment_count; ++i) {
    if (const Status s = check_joints(segment_joints(joints, i), geometry.segments[i]); s != Status::ok) return s;
  }
  return Status::ok;
}

template <typename S, int Max>
Status cables_from_joints(const JointVector<S, Max>& joints, const RobotGeometry<S, Max>& geometry,
                          CableVector<S, Max>& cables_mm) {
  if (const Status s = check_joints(joints, geometry); s != Status::ok) return s;
  CableVector<S, Max> result(geometry.cable_count());
  for (int i = 0, first = 0; i < geometry.segment_count; first += geometry.segments[i].cables.count, ++i) {
    SegmentCables<S> segment_cables;
    if (const Status s = cables_from_joints(segment_joints(joints, i), geometry.segments[i], segment_cables);
        s != Status::ok) {
      return s;
    }
    result.segment(first, segment_cables.size()) = segment_cables;
  }
  cables_mm = result;
  return Status::ok;
}

template <typename Derived>
typename Derived::PlainObject bend_from_joints(const Eigen::MatrixBase<Derived>& joints) {
  typename Derived::PlainObject bend(joints.size());
  for (Eigen::Index i = 0; i < joints.size() / 2; ++i) {
    bend.template segment<2>(2 * i) = bend_from_joints(segment_joints(joints, static_cast<int>(i)));
  }
  return bend;
}

template <typename Derived>
typename Derived::PlainObject joints_from_bend(const Eigen::MatrixBase<Derived>& bend) {
  using S = typename Derived::Scalar;
  typename Derived::PlainObject joints(bend.size());
  for (Eigen::Index i = 0; i < bend.size() / 2; ++i) {
    const SegmentJoints<S> q = joints_from_bend<S>(bend.template segment<2>(2 * i));
    joints[2 * i] = q.alpha_rad;
    joints[2 * i + 1] = q.theta_rad;
  }
  return joints;
}

// Unchecked fast path for callers that have already validated their input
// (the runtime cycle, the inverse kinematics iteration).
template <typename S, int Max>
Pose<S> forward_kinematics_bend(const JointVector<S, Max>& bend, const RobotGeometry<S, Max>& geometry) {
  Pose<S> tip;
  for (int i = 0; i < geometry.segment_count; ++i) {
    tip = tip * segment_pose<S>(bend.template segment<2>(2 * i), geometry.segments[i].backbone_length_mm);
  }
  return tip;
}

template <typename S, int Max>
Status forward_kinematics(const JointVector<S, Max>& joints, const RobotGeometry<S, Max>& geometry, Pose<S>& tip) {
  if (const Status s = check_joints(joints, geometry); s != Status::ok) return s;
  tip = forward_kinematics_bend(bend_from_joints(joints), geometry);
  return Status::ok;
}

// Spatial Jacobian of the tip pose with respect to the bend vector:
// T(b + db) = exp(hat(J db)) T(b) + O(|db|^2), twists in the base frame,
// ordered (v, omega). Column 2i+k is Ad_{T_0,i} applied to segment i's own
// twist. Also returns the tip pose, which it computes on the way.
template <typename S, int Max>
void tip_jacobian_bend(const JointVector<S, Max>& bend, const RobotGeometry<S, Max>& geometry, Pose<S>& tip,
                       Jacobian<S, Max>& jacobian) {
  jacobian.resize(6, 2 * geometry.segment_count);
  tip = Pose<S>::identity();
  for (int i = 0; i < geometry.segment_count; ++i) {
    const Vec2<S> b = bend.template segment<2>(2 * i);
    const S L = geometry.segments[i].backbone_length_mm;
    Eigen::Matrix<S, 6, 2> local = segment_bend_twists<S>(b, L);
    apply_adjoint(tip, local);
    jacobian.template middleCols<2>(2 * i) = local;
    tip = tip * segment_pose<S>(b, L);
  }
}

// The same with respect to the paper's joint variables (alpha_i, theta_i).
// The alpha columns are zero for straight segments: the true singularity.
template <typename S, int Max>
Status tip_jacobian(const JointVector<S, Max>& joints, const RobotGeometry<S, Max>& geometry, Pose<S>& tip,
                    Jacobian<S, Max>& jacobian) {
  if (const Status s = check_joints(joints, geometry); s != Status::ok) return s;
  jacobian.resize(6, 2 * geometry.segment_count);
  tip = Pose<S>::identity();
  for (int i = 0; i < geometry.segment_count; ++i) {
    const SegmentJoints<S> q = segment_joints(joints, i);
    const S L = geometry.segments[i].backbone_length_mm;
    Eigen::Matrix<S, 6, 2> local = segment_joint_twists<S>(q, L);
    apply_adjoint(tip, local);
    jacobian.template middleCols<2>(2 * i) = local;
    tip = tip * segment_pose<S>(bend_from_joints(q), L);
  }
  return Status::ok;
}

}  // namespace cdcr::model
