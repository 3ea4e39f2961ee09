#pragma once
// The runtime's IK settings for callers off the cycle (`cdcr ik`, the IK
// bench): the same bounds, restarts, damping and start as a request on the
// board, so that what a user tries on the PC is what the board does.

#include <algorithm>

#include "cdcr/firmware/capacity.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/ik_solver.hpp"
#include "cdcr/model/inverse_kinematics.hpp"

namespace cdcr::firmware {

// A request's bounds and restarts, as the runtime configures its solver.
template <typename S>
model::IkSolverOptions<S> runtime_solver_options() {
  model::IkSolverOptions<S> options;
  options.max_corrections = kMaxIkCorrections;
  options.max_iterations = kMaxIkIterations;
  options.max_restarts = kMaxIkRestarts;
  return options;
}

template <typename S>
model::IkOptions<S> runtime_ik_options() {
  model::IkOptions<S> options;
  options.max_iterations = kMaxIkIterations;
  options.max_restarts = kMaxIkRestarts;
  options.initial_damping = model::IkSolverOptions<S>{}.initial_damping;
  return options;
}

// The start of a request with nothing better: alpha 0 and a slight bend on
// every segment.
template <typename S, int Max>
model::JointVector<S, Max> ik_straight_start(const model::RobotGeometry<S, Max>& geometry) {
  model::JointVector<S, Max> joints(2 * geometry.segment_count);
  for (int i = 0; i < geometry.segment_count; ++i) {
    joints[2 * i] = S(0);
    joints[2 * i + 1] = std::min(S(kIkStraightStartThetaRad), geometry.segments[i].theta_max_rad);
  }
  return joints;
}

// The fraction of the way to the preferred bends each step takes in the
// pose task's null space (model::IkPreference).
inline constexpr double kIkPreferenceGain = 0.3;

// Where a request prefers its solution: in the middle of the bends the
// image's model was fitted on (bend-vector inputs: the centre of each
// input's range, each weighted by the inverse square of its half-width; the
// variance is low there and the correction interpolates), and in any case
// away from the theta limit. Without ranges in bend coordinates (joint-
// angle inputs, a v1 image, or no image: the nominal model) none: the
// nominal model is as sure everywhere, and on its full range a pull towards
// the straight robot cost 99.70 -> 99.45 % of the targets, the limit's
// margin alone 99.70 -> 99.50 % (IK bench, seed 26).
template <typename S, int Max>
model::IkPreference<S, Max> ik_preference(const model::RobotGeometry<S, Max>& geometry,
                                          const model::ImageView* image) {
  model::IkPreference<S, Max> preference;
  const int columns = 2 * geometry.segment_count;
  preference.centre.setZero(columns);
  preference.weight.setZero(columns);
  if (image == nullptr || image->encoding == model::InputEncoding::joint_angles || image->input_min == nullptr ||
      image->segment_count != geometry.segment_count) {
    return preference;
  }
  preference.gain = S(kIkPreferenceGain);
  S largest = S(0);
  for (int d = 0; d < columns; ++d) {
    const S half_width = S(0.5) * (S(image->input_max[d]) - S(image->input_min[d]));
    if (!(half_width > S(0))) return preference;
    preference.centre[d] = S(0.5) * (S(image->input_max[d]) + S(image->input_min[d]));
    preference.weight[d] = S(1) / (half_width * half_width);
    largest = std::max(largest, preference.weight[d]);
  }
  preference.weight /= largest;
  return preference;
}

// A nominal target solved as the board solves it, then to double precision:
// the board's solver type in float with the runtime's settings finds the
// basin (which targets converge, from which start, depends on the
// arithmetic: the same settings in double converged on 97.65 % of the full
// range's targets where float did on 99.5 %), and up to `polish_iterations`
// double iterations from its answer bring it to the double tolerance.
// A board solve that ends short is polished all the same; the result says
// whether the double solve converged.
template <int Max>
model::IkResult<double, Max> solve_ik_as_on_the_board(const model::Pose<double>& target, model::IkTargetKind kind,
                                                      const model::RobotGeometry<double, Max>& geometry,
                                                      const model::JointVector<double, Max>& initial_joints,
                                                      int board_iterations = kMaxIkIterations,
                                                      int polish_iterations = 100) {
  model::IkOptions<float> board_options = runtime_ik_options<float>();
  board_options.max_iterations = board_iterations;
  const model::RobotGeometry<float, Max> geometry_f = geometry.template cast<float>();
  const model::JointVector<float, Max> initial_f = initial_joints.template cast<float>();
  const model::IkResult<float, Max> board =
      kind == model::IkTargetKind::pose
          ? model::solve_ik(target.template cast<float>(), geometry_f, initial_f, board_options)
          : model::solve_ik_position(model::Vec3<float>(target.position_mm.template cast<float>()), geometry_f,
                                     initial_f, board_options);
  // A float answer on the limit can lie one rounding step beyond the
  // double theta_max.
  model::JointVector<double, Max> start = initial_joints;
  if (board.joints.size() == initial_joints.size()) {
    start = board.joints.template cast<double>();
    for (int i = 0; i < geometry.segment_count; ++i) {
      start[2 * i + 1] = std::clamp(start[2 * i + 1], 0.0, geometry.segments[i].theta_max_rad);
    }
    if (model::check_joints(start, geometry) != model::Status::ok) start = initial_joints;
  }
  model::IkOptions<double> polish = runtime_ik_options<double>();
  polish.max_iterations = polish_iterations;
  model::IkResult<double, Max> result =
      kind == model::IkTargetKind::pose
          ? model::solve_ik(target, geometry, start, polish)
          : model::solve_ik_position(model::Vec3<double>(target.position_mm), geometry, start, polish);
  result.iterations += board.iterations;
  return result;
}

}  // namespace cdcr::firmware
