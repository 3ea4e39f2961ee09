#pragma once
// What every part of an IK solve measures against (ik_solver.hpp): the
// geometry, the options, the target and the weight that puts its
// orientation residual in millimetres.

#include <algorithm>
#include <limits>

#include "cdcr/model/chain.hpp"
#include "cdcr/model/geometry.hpp"
#include "cdcr/model/ik/options.hpp"
#include "cdcr/model/se3.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model::ik {

template <typename S, int Max>
struct Problem {
  using Joints = JointVector<S, Max>;
  using Residual = Eigen::Matrix<S, 6, 1>;

  const RobotGeometry<S, Max>* geometry = nullptr;
  IkSolverOptions<S> options{};
  S weight = S(1);
  Pose<S> target{};
  IkTargetKind kind = IkTargetKind::pose;

  // The orientation weight: the options', or by default the mean backbone
  // length (1 rad of bend moves a segment tip by about that much).
  void configure(const RobotGeometry<S, Max>& robot, const IkSolverOptions<S>& solver_options) {
    geometry = &robot;
    options = solver_options;
    weight = solver_options.orientation_weight_mm_per_rad;
    if (!(weight > S(0))) {
      weight = S(0);
      for (int i = 0; i < robot.segment_count; ++i) weight += robot.segments[i].backbone_length_mm;
      weight /= S(robot.segment_count);
    }
  }

  // Residual of the target against a tip pose: position (mm) and, for pose
  // targets, the weighted rotation vector of R_target R^T.
  void residual_of(const Pose<S>& tip, Residual& residual, S& position_error, S& orientation_error) const {
    const Vec3<S> dp = target.position_mm - tip.position_mm;
    position_error = dp.norm();
    residual.template head<3>() = dp;
    if (kind == IkTargetKind::pose) {
      const Vec3<S> dr = log_so3<S>(Mat3<S>(target.rotation * tip.rotation.transpose()));
      orientation_error = dr.norm();
      residual.template tail<3>() = weight * dr;
    } else {
      orientation_error = S(0);
      residual.template tail<3>().setZero();
    }
  }

  bool within_tolerance(S position_error, S orientation_error) const {
    return position_error <= options.position_tolerance_mm && orientation_error <= options.orientation_tolerance_rad;
  }

  bool on_limit(int segment, const Joints& bend) const {
    const S theta = bend.template segment<2>(2 * segment).norm();
    return theta >= geometry->segments[segment].theta_max_rad * (S(1) - S(16) * std::numeric_limits<S>::epsilon());
  }

  Joints clamped_joints(const Joints& bend) const {
    Joints joints = joints_from_bend(bend);
    for (int i = 0; i < geometry->segment_count; ++i) {
      // A point on the limit circle can sit one rounding step outside it.
      joints[2 * i + 1] = std::min(joints[2 * i + 1], geometry->segments[i].theta_max_rad);
    }
    return joints;
  }
};

}  // namespace cdcr::model::ik
