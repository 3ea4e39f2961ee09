#pragma once
// Inverse kinematics by damped least squares (Levenberg-Marquardt): a target
// tip pose, or a target position alone, to joint variables and cable lengths.
//
// * The iteration runs in bend-vector coordinates, where the model is smooth
//   and the limit theta <= theta_max is a disc that a step is projected onto.
// * The iteration count is bounded, so a caller on a fixed-rate cycle knows
//   the worst case. The result says whether the tolerance was reached; when it
//   was not, it still holds the best configuration found.
// * An optional correction term eps(b) turns the nominal model into the
//   compensated one, T_c(b) = exp(eps(b)) T(b), with the Jacobian
//   J_c = J_l(eps) d(eps)/db + Ad_exp(eps) J. The runtime plugs in the GP
//   mean and its analytic gradient there.

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>

#include <Eigen/Cholesky>

#include "cdcr/model/chain.hpp"
#include "cdcr/model/compensation.hpp"
#include "cdcr/model/geometry.hpp"
#include "cdcr/model/se3.hpp"
#include "cdcr/model/status.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model {

// The identity correction: the nominal model. A correction is any callable
//   Status(const JointVector<S, Max>& bend, Twist<S>& eps, Jacobian<S, Max>& d_eps_d_bend)
// that evaluates eps and its derivative with respect to the stacked bend vector.
struct NoCorrection {
  template <typename Bend, typename S, typename DerivativeMatrix>
  Status operator()(const Bend& bend, Twist<S>& eps, DerivativeMatrix& d_eps_d_bend) const {
    eps.setZero();
    d_eps_d_bend.setZero(6, bend.size());
    return Status::ok;
  }
};

template <typename S>
struct IkOptions {
  int max_iterations = 100;
  S position_tolerance_mm = std::is_same_v<S, float> ? S(2e-3) : S(1e-9);
  S orientation_tolerance_rad = std::is_same_v<S, float> ? S(2e-5) : S(1e-11);
  // Converts the orientation residual to millimetres so that one step weighs
  // both parts; zero means the mean backbone length (1 rad of bend moves a
  // segment tip by about that much).
  S orientation_weight_mm_per_rad = S(0);
  S initial_damping = S(1e-3);
};

template <typename S, int Max = kMaxSegments>
struct IkResult {
  Status status = Status::ik_not_converged;
  int iterations = 0;
  S position_error_mm = std::numeric_limits<S>::infinity();
  S orientation_error_rad = std::numeric_limits<S>::infinity();
  JointVector<S, Max> joints;
  CableVector<S, Max> cables_mm;

  bool converged() const { return status == Status::ok; }
};

namespace detail {

template <typename S, int Max>
void project_onto_limits(JointVector<S, Max>& bend, const RobotGeometry<S, Max>& geometry) {
  for (int i = 0; i < geometry.segment_count; ++i) {
    const S theta = bend.template segment<2>(2 * i).norm();
    const S limit = geometry.segments[i].theta_max_rad;
    if (theta > limit) bend.template segment<2>(2 * i) *= limit / theta;
  }
}

template <typename S, int Max, typename Correction>
Status evaluate_model(const JointVector<S, Max>& bend, const RobotGeometry<S, Max>& geometry,
                      const Correction& correction, Pose<S>& tip, Jacobian<S, Max>& jacobian) {
  tip_jacobian_bend(bend, geometry, tip, jacobian);
  if constexpr (!std::is_same_v<Correction, NoCorrection>) {
    Twist<S> eps;
    Jacobian<S, Max> d_eps;
    if (const Status s = correction(bend, eps, d_eps); s != Status::ok) return s;
    if (!eps.allFinite() || !d_eps.allFinite() || d_eps.cols() != jacobian.cols()) return Status::correction_failed;
    const Pose<S> correction_pose = exp(eps);
    apply_adjoint(correction_pose, jacobian);
    jacobian.noalias() += left_jacobian(eps) * d_eps;
    tip = correction_pose * tip;
  }
  return Status::ok;
}

// A correction may offer `Status value(bend, eps)`, the twist without its
// derivative; trial steps that the iteration may reject then skip the
// gradient, which for a GP costs several times the value.
template <typename Correction, typename Bend, typename TwistType, typename = void>
struct has_value_only : std::false_type {};
template <typename Correction, typename Bend, typename TwistType>
struct has_value_only<Correction, Bend, TwistType,
                      std::void_t<decltype(std::declval<const Correction&>().value(std::declval<const Bend&>(),
                                                                                   std::declval<TwistType&>()))>>
    : std::true_type {};

// The model's tip pose alone, for a trial step.
template <typename S, int Max, typename Correction>
Status evaluate_pose(const JointVector<S, Max>& bend, const RobotGeometry<S, Max>& geometry,
                     const Correction& correction, Pose<S>& tip) {
  tip = forward_kinematics_bend(bend, geometry);
  if constexpr (!std::is_same_v<Correction, NoCorrection>) {
    Twist<S> eps;
    if constexpr (has_value_only<Correction, JointVector<S, Max>, Twist<S>>::value) {
      if (const Status s = correction.value(bend, eps); s != Status::ok) return s;
    } else {
      Jacobian<S, Max> unused;
      if (const Status s = correction(bend, eps, unused); s != Status::ok) return s;
    }
    if (!eps.allFinite()) return Status::correction_failed;
    tip = exp(eps) * tip;
  }
  return Status::ok;
}

// Position error (mm) and, for pose targets, the weighted rotation vector of
// R_target R^T.
template <int Rows, typename S>
void residual_of(const Pose<S>& target, const Pose<S>& tip, S orientation_weight,
                 Eigen::Matrix<S, Rows, 1>& residual, S& position_error, S& orientation_error) {
  const Vec3<S> dp = target.position_mm - tip.position_mm;
  position_error = dp.norm();
  residual.template head<3>() = dp;
  if constexpr (Rows == 6) {
    const Vec3<S> dr = log_so3<S>(Mat3<S>(target.rotation * tip.rotation.transpose()));
    orientation_error = dr.norm();
    residual.template tail<3>() = orientation_weight * dr;
  } else {
    orientation_error = S(0);
  }
}

// Rows matching residual_of: the tip point's velocity (v + omega x p) and the
// weighted angular velocity.
template <int Rows, typename S, int Max>
void jacobian_rows(const Pose<S>& tip, const Jacobian<S, Max>& spatial, S orientation_weight,
                   Eigen::Matrix<S, Rows, Eigen::Dynamic, Eigen::RowMajor, Rows, 2 * Max>& rows) {
  rows.resize(Rows, spatial.cols());
  rows.template topRows<3>() = spatial.template topRows<3>() - hat3<S>(tip.position_mm) * spatial.template bottomRows<3>();
  if constexpr (Rows == 6) rows.template bottomRows<3>() = orientation_weight * spatial.template bottomRows<3>();
}

template <int Rows, typename S, int Max, typename Correction>
IkResult<S, Max> solve(const Pose<S>& target, const RobotGeometry<S, Max>& geometry,
                       const JointVector<S, Max>& initial_joints, const IkOptions<S>& options,
                       const Correction& correction) {
  IkResult<S, Max> result;
  if (const Status s = check_joints(initial_joints, geometry); s != Status::ok) {
    result.status = s;
    return result;
  }
  if (!target.all_finite()) {
    result.status = Status::non_finite_input;
    return result;
  }

  S weight = options.orientation_weight_mm_per_rad;
  if (!(weight > S(0))) {
    weight = S(0);
    for (int i = 0; i < geometry.segment_count; ++i) weight += geometry.segments[i].backbone_length_mm;
    weight /= S(geometry.segment_count);
  }
  const S position_tolerance = options.position_tolerance_mm;
  const S orientation_tolerance = options.orientation_tolerance_rad;

  using Residual = Eigen::Matrix<S, Rows, 1>;
  using Rows_t = Eigen::Matrix<S, Rows, Eigen::Dynamic, Eigen::RowMajor, Rows, 2 * Max>;
  using Normal = Eigen::Matrix<S, Rows, Rows>;

  JointVector<S, Max> bend = bend_from_joints(initial_joints);
  Pose<S> tip;
  Residual residual;
  Rows_t rows;
  S position_error = S(0);
  S orientation_error = S(0);
  if (const Status s = evaluate_pose(bend, geometry, correction, tip); s != Status::ok) {
    result.status = s;
    return result;
  }
  residual_of<Rows>(target, tip, weight, residual, position_error, orientation_error);
  S cost = residual.squaredNorm();
  // The Jacobian is evaluated only where a step starts, never at rejected
  // trial points or at the final one.
  bool rows_current = false;

  const S min_damping = std::numeric_limits<S>::epsilon();
  const S max_damping = S(1e8);
  S damping = options.initial_damping;
  result.status = Status::ik_not_converged;

  int iteration = 0;
  for (;;) {
    if (position_error <= position_tolerance && orientation_error <= orientation_tolerance) {
      result.status = Status::ok;
      break;
    }
    if (iteration >= options.max_iterations || damping > max_damping) break;
    ++iteration;

    if (!rows_current) {
      Jacobian<S, Max> spatial;
      if (const Status s = evaluate_model(bend, geometry, correction, tip, spatial); s != Status::ok) {
        result.status = s;
        break;
      }
      jacobian_rows<Rows, S, Max>(tip, spatial, weight, rows);
      rows_current = true;
    }

    // Coefficient-wise products: Eigen's general product paths can fall back
    // to heap workspace, which a board build must not link.
    Normal normal = rows.lazyProduct(rows.transpose());
    const S scale = normal.trace() / S(Rows);
    normal.diagonal().array() += damping * scale + std::numeric_limits<S>::min();
    const Residual y = normal.ldlt().solve(residual);
    JointVector<S, Max> trial = bend + rows.transpose().lazyProduct(y);
    project_onto_limits(trial, geometry);

    Pose<S> trial_tip;
    if (const Status s = evaluate_pose(trial, geometry, correction, trial_tip); s != Status::ok) {
      result.status = s;
      break;
    }
    Residual trial_residual;
    S trial_position_error = S(0);
    S trial_orientation_error = S(0);
    residual_of<Rows>(target, trial_tip, weight, trial_residual, trial_position_error, trial_orientation_error);
    const S trial_cost = trial_residual.squaredNorm();
    if (trial_cost < cost) {
      bend = trial;
      residual = trial_residual;
      cost = trial_cost;
      position_error = trial_position_error;
      orientation_error = trial_orientation_error;
      rows_current = false;
      damping = std::max(damping * S(0.1), min_damping);
    } else {
      damping *= S(10);
    }
  }

  result.iterations = iteration;
  result.position_error_mm = position_error;
  result.orientation_error_rad = orientation_error;
  result.joints = joints_from_bend(bend);
  for (int i = 0; i < geometry.segment_count; ++i) {
    // The projection can leave theta one rounding step above the limit.
    result.joints[2 * i + 1] = std::min(result.joints[2 * i + 1], geometry.segments[i].theta_max_rad);
  }
  if (const Status s = cables_from_joints(result.joints, geometry, result.cables_mm); s != Status::ok) {
    result.status = s;
  }
  return result;
}

}  // namespace detail

// Full pose target: position and orientation.
template <typename S, int Max, typename Correction = NoCorrection>
IkResult<S, Max> solve_ik(const Pose<S>& target, const RobotGeometry<S, Max>& geometry,
                          const JointVector<S, Max>& initial_joints, const IkOptions<S>& options = {},
                          const Correction& correction = {}) {
  return detail::solve<6>(target, geometry, initial_joints, options, correction);
}

// Position-only target: the orientation of the tip is left free.
template <typename S, int Max, typename Correction = NoCorrection>
IkResult<S, Max> solve_ik_position(const Vec3<S>& target_mm, const RobotGeometry<S, Max>& geometry,
                                   const JointVector<S, Max>& initial_joints, const IkOptions<S>& options = {},
                                   const Correction& correction = {}) {
  Pose<S> target;
  target.position_mm = target_mm;
  return detail::solve<3>(target, geometry, initial_joints, options, correction);
}

}  // namespace cdcr::model
