#pragma once
// Inverse kinematics in one call: a target tip pose, or a target position
// alone, to joint variables and cable lengths, for callers off the
// fixed-rate cycle (the `cdcr ik` command, tests, tools). It runs the
// resumable solver of ik_solver.hpp to the end: one method for the PC and
// the boards.
//
// * The iteration runs in bend-vector coordinates, where the model is smooth;
//   the limit theta <= theta_max is handled by an active set.
// * The iteration count is bounded (max_iterations nominal LM steps), so a
//   caller knows the worst case. The result says whether the tolerance was
//   reached; when it was not, it still holds the best configuration found.
// * An optional correction term eps(b) turns the nominal model into the
//   compensated one, T_c(b) = exp(eps(b)) T(b). The runtime plugs in the GP
//   mean there. Only eps is evaluated, never its derivative: the solver
//   learns the slope it needs from the evaluations (see ik_solver.hpp).

#include <limits>
#include <type_traits>

#include "cdcr/model/chain.hpp"
#include "cdcr/model/geometry.hpp"
#include "cdcr/model/ik_solver.hpp"
#include "cdcr/model/status.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model {

template <typename S>
struct IkOptions {
  int max_iterations = 100;
  S position_tolerance_mm = std::is_same_v<S, float> ? S(2e-3) : S(1e-9);
  S orientation_tolerance_rad = std::is_same_v<S, float> ? S(2e-5) : S(1e-11);
  // Converts the orientation residual to millimetres so that one step weighs
  // both parts; zero means the mean backbone length.
  S orientation_weight_mm_per_rad = S(0);
  S initial_damping = S(1e-3);
  // Starts after the first one when a start stalls (IkSolverOptions).
  int max_restarts = 3;
};

template <typename S, int Max = kMaxSegments>
struct IkResult {
  Status status = Status::ik_not_converged;
  int iterations = 0;  // nominal LM iterations
  int corrections = 0; // evaluations of the correction term
  S position_error_mm = std::numeric_limits<S>::infinity();
  S orientation_error_rad = std::numeric_limits<S>::infinity();
  JointVector<S, Max> joints;
  CableVector<S, Max> cables_mm;

  bool converged() const { return status == Status::ok; }
};

namespace detail {

template <typename S, int Max, typename Correction>
IkResult<S, Max> solve_to_end(const Pose<S>& target, IkTargetKind kind, const RobotGeometry<S, Max>& geometry,
                              const JointVector<S, Max>& initial_joints, const IkOptions<S>& options,
                              const Correction& correction) {
  IkResult<S, Max> result;
  if (const Status s = check_joints(initial_joints, geometry); s != Status::ok) {
    result.status = s;
    return result;
  }
  IkSolverOptions<S> solver_options;
  solver_options.position_tolerance_mm = options.position_tolerance_mm;
  solver_options.orientation_tolerance_rad = options.orientation_tolerance_rad;
  solver_options.orientation_weight_mm_per_rad = options.orientation_weight_mm_per_rad;
  solver_options.initial_damping = options.initial_damping;
  solver_options.max_iterations = options.max_iterations;
  solver_options.max_restarts = options.max_restarts;
  IkSolver<S, Max, Correction> solver;
  solver.configure(geometry, correction, solver_options);
  if (const Status s = solver.start(target, kind, initial_joints); s != Status::ok) {
    result.status = s;
    return result;
  }
  solver.run_to_end();
  result.iterations = solver.iterations();
  result.corrections = solver.corrections();
  if (solver.state() == IkSolveState::failed) {
    result.status = solver.status();
    return result;
  }
  result.status = solver.state() == IkSolveState::converged ? Status::ok : Status::ik_not_converged;
  result.position_error_mm = solver.best_position_error_mm();
  result.orientation_error_rad = solver.best_orientation_error_rad();
  result.joints = solver.best_joints();
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
  return detail::solve_to_end(target, IkTargetKind::pose, geometry, initial_joints, options, correction);
}

// Position-only target: the orientation of the tip is left free.
template <typename S, int Max, typename Correction = NoCorrection>
IkResult<S, Max> solve_ik_position(const Vec3<S>& target_mm, const RobotGeometry<S, Max>& geometry,
                                   const JointVector<S, Max>& initial_joints, const IkOptions<S>& options = {},
                                   const Correction& correction = {}) {
  Pose<S> target;
  target.position_mm = target_mm;
  return detail::solve_to_end(target, IkTargetKind::position, geometry, initial_joints, options, correction);
}

}  // namespace cdcr::model
