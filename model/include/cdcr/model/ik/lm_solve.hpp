#pragma once
// The linearised solve between two correction evaluations (ik_solver.hpp):
// damped least-squares (Levenberg-Marquardt) steps on
//     exp(eps_k + E (b - b_k)) T(b) = target
// with the analytic nominal Jacobian, and the theta limits as an active set:
// a segment that a step would carry outside its limit disc moves only along
// the limit circle until the cost's descent points back inside. A step may
// carry the preference's pull (IkPreference, ik/options.hpp) as well,
// projected into the null space of the pose task.

#include <algorithm>
#include <cstdint>
#include <limits>

#include <Eigen/Cholesky>

#include "cdcr/model/chain.hpp"
#include "cdcr/model/geometry.hpp"
#include "cdcr/model/ik/linearisation.hpp"
#include "cdcr/model/ik/options.hpp"
#include "cdcr/model/ik/problem.hpp"
#include "cdcr/model/ik/solve_flow.hpp"
#include "cdcr/model/se3.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model::ik {

// The preference's part of an LM step: a pull towards the preferred bends.
template <typename S, int Max>
class Preference {
 public:
  using Joints = JointVector<S, Max>;

  // Off (gain zero) unless it fits the geometry and is finite.
  void set(const IkPreference<S, Max>& preference, const RobotGeometry<S, Max>* geometry) {
    preference_ = preference;
    if (geometry == nullptr || !(preference_.gain > S(0)) || preference_.centre.size() != 2 * geometry->segment_count ||
        preference_.weight.size() != 2 * geometry->segment_count || !preference_.centre.allFinite() ||
        !preference_.weight.allFinite()) {
      preference_.gain = S(0);
    }
  }
  void clear() { preference_ = IkPreference<S, Max>{}; }

  // Within 20 tolerances of the target (where a stall counts as the
  // arithmetic's floor) the steps are the pose task's alone: the
  // preference's drift, however small, spoils the secant slope the last few
  // um need (figures: tools/bench/README.md, IK section).
  bool applies(bool may_prefer, const SolveFlow& flow, S position_error, const IkSolverOptions<S>& options) const {
    return may_prefer && flow.preference_included() && preference_.gain > S(0) &&
           position_error > S(20) * options.position_tolerance_mm;
  }

  // Adds to the pose task's step J^T (J J^T + damping)^-1 r that of the
  // pull z on the same factor: z less what the pose task sees of it,
  // z - J^T (J J^T + damping)^-1 J z, on the reduced coordinates `used`
  // (two per free segment, one along the limit circle per active one).
  template <int Rows, typename Used, typename Factor, typename Step>
  void add_to_step(Step& step, const Used& used, const Factor& factor, int columns, const Joints& bend,
                   const bool* active, const Vec2<S>* tangent, const RobotGeometry<S, Max>& geometry) const {
    Step z(columns);
    columns = 0;
    for (int i = 0; i < geometry.segment_count; ++i) {
      const Vec2<S> b = bend.template segment<2>(2 * i);
      Vec2<S> pull = preference_.weight.template segment<2>(2 * i).cwiseProduct(
          preference_.centre.template segment<2>(2 * i) - b);
      const S theta = b.norm();
      const S keep_within = (S(1) - preference_.limit_margin) * geometry.segments[i].theta_max_rad;
      if (theta > keep_within) pull -= ((theta - keep_within) / theta) * b;
      pull *= preference_.gain;
      if (active[i]) {
        z[columns++] = tangent[i].dot(pull);
      } else {
        z.template segment<2>(columns) = pull;
        columns += 2;
      }
    }
    const Eigen::Matrix<S, Rows, 1> seen = used.lazyProduct(z);
    Step null_step = z - used.transpose().lazyProduct(factor.solve(seen));
    // Never longer than the pose task's own step: the preference's leak
    // through the damping then stays a fraction of the step, and the last
    // steps before a solution are left alone (tools/bench/README.md, IK
    // section).
    const S longest = step.norm();
    const S length = null_step.norm();
    if (length > longest) null_step *= longest / length;
    step += null_step;
  }

 private:
  IkPreference<S, Max> preference_{};
};

template <typename S, int Max>
class LmSolve {
 public:
  using Joints = JointVector<S, Max>;
  using Residual = Eigen::Matrix<S, 6, 1>;
  static constexpr int kMaxColumns = 2 * Max;

  // A new linearised solve after an outer step at lin.point, whose exact
  // errors were position_error and orientation_error: from that point, or
  // from where a streamed target's steps have taken the last one since.
  template <bool Sliced>
  void begin(const Problem<S, Max>& problem, const Linearisation<S, Max>& lin, const SolveFlow& flow,
             S position_error, S orientation_error, bool had_damping) {
    const IkSolverOptions<S>& options = problem.options;
    if (!flow.streamed_point()) bend_ = lin.point;
    iterations_ = 0;
    slow_steps_ = 0;
    if (!had_damping || position_error > options.keep_damping_within_mm) damping_ = options.initial_damping;
    for (int i = 0; i < problem.geometry->segment_count; ++i) active_[i] = problem.on_limit(i, bend_);
    evaluate_pose(problem, lin, flow, bend_, tip_);
    problem.residual_of(tip_, residual_, position_error_, orientation_error_);
    cost_ = residual_.squaredNorm();
    if constexpr (Sliced) {
      // Inexact solves: far from the target, the linearised model need not
      // be solved much beyond the accuracy the next evaluation will show.
      position_goal_ = std::max(S(0.5) * options.position_tolerance_mm, S(0.02) * position_error);
      orientation_goal_ = std::max(S(0.5) * options.orientation_tolerance_rad, S(0.02) * orientation_error);
    } else {
      // An evaluation in one call is cheap: solve to the tolerance.
      position_goal_ = options.position_tolerance_mm;
      orientation_goal_ = options.orientation_tolerance_rad;
    }
  }

  // The target moved: the point's tip stays, its residual is new.
  void rescore(const Problem<S, Max>& problem) {
    problem.residual_of(tip_, residual_, position_error_, orientation_error_);
    cost_ = residual_.squaredNorm();
  }

  bool done() const { return position_error_ <= position_goal_ && orientation_error_ <= orientation_goal_; }
  void count_iteration() { ++iterations_; }
  // The damping has blown up: no step helps.
  bool stalled() const { return damping_ > S(1e8); }
  // Stalled where the evaluation was made, far from the target: a local
  // minimum of the model, for a restart.
  bool stuck(const Joints& evaluated_point, const IkSolverOptions<S>& options) const {
    return stalled() && bend_ == evaluated_point && position_error_ > options.restart_above_mm;
  }
  // Whether the next evaluation should take over: the linearised solve is
  // done or stalled or, when evaluations are sliced (and so dear), its steps
  // have slowed (the linearised model's own minimum is near, and it is not
  // exact far from b_k) or used their bound.
  template <bool Sliced>
  bool hand_over(const IkSolverOptions<S>& options) const {
    const bool give_up = Sliced && (slow_steps_ >= 2 || iterations_ >= options.max_inner_iterations);
    return done() || stalled() || give_up;
  }
  const Joints& bend() const { return bend_; }
  S position_error() const { return position_error_; }
  S orientation_error() const { return orientation_error_; }

  // The linearised model's Jacobian at the current point, as residual rows.
  // Position targets use the same six rows with the orientation rows and
  // residual zero: the damped step is then the three-row one, and the
  // firmware carries one copy of the code.
  template <int Rows>
  void update_rows(const Problem<S, Max>& problem, const Linearisation<S, Max>& lin, SolveFlow& flow) {
    const int segments = problem.geometry->segment_count;
    Pose<S> tip;
    Jacobian<S, Max> spatial;
    tip_jacobian_bend(bend_, *problem.geometry, tip, spatial);
    const Twist<S> eps = lin.eps_at(bend_, flow);
    const Pose<S> correction_pose = exp(eps);
    apply_adjoint(correction_pose, spatial);
    if (flow.slope_known()) spatial.noalias() += left_jacobian(eps).lazyProduct(lin.slope);
    tip = correction_pose * tip;
    rows_.setZero();
    rows_.template topLeftCorner<3, kMaxColumns>().leftCols(2 * segments) =
        spatial.template topRows<3>() - hat3<S>(tip.position_mm) * spatial.template bottomRows<3>();
    if (problem.kind == IkTargetKind::pose) {
      rows_.template bottomLeftCorner<3, kMaxColumns>().leftCols(2 * segments) =
          problem.weight * spatial.template bottomRows<3>();
    }
    flow.on(Event::rows_updated);
    // Segments on the limit leave the active set when descent points inside.
    for (int i = 0; i < segments; ++i) {
      if (!active_[i]) continue;
      const Vec2<S> b = bend_.template segment<2>(2 * i);
      const Vec2<S> descent = rows_.template topRows<Rows>().template middleCols<2>(2 * i).transpose() *
                              residual_.template head<Rows>();
      if (b.dot(descent) < S(0)) active_[i] = false;
    }
  }

  // The damped step from the current point on the current rows, kept when
  // the linearised model's cost falls; the damping adapts either way.
  template <int Rows>
  void try_step(const Problem<S, Max>& problem, const Linearisation<S, Max>& lin, const Preference<S, Max>& preference,
                SolveFlow& flow, bool may_prefer) {
    const RobotGeometry<S, Max>& geometry = *problem.geometry;
    const int segments = geometry.segment_count;
    Joints trial;
    bool stepped = false;
    const bool preferred = preference.applies(may_prefer, flow, position_error_, problem.options);
    // Each pass may add segments to the active set; at most one pass per segment.
    for (int pass = 0; pass <= segments && !stepped; ++pass) {
      trial = step<Rows>(problem, preference, preferred);
      stepped = true;
      for (int i = 0; i < segments; ++i) {
        if (active_[i]) continue;
        const S theta = trial.template segment<2>(2 * i).norm();
        if (theta > geometry.segments[i].theta_max_rad) {
          active_[i] = true;
          stepped = false;
        }
      }
    }
    // Whatever is left outside (all passes used) goes back onto the circle.
    for (int i = 0; i < segments; ++i) {
      const S theta = trial.template segment<2>(2 * i).norm();
      const S limit = geometry.segments[i].theta_max_rad;
      if ((active_[i] || theta > limit) && theta > S(0)) trial.template segment<2>(2 * i) *= limit / theta;
    }

    Pose<S> trial_tip;
    evaluate_pose(problem, lin, flow, trial, trial_tip);
    Residual trial_residual;
    S trial_position_error = S(0);
    S trial_orientation_error = S(0);
    problem.residual_of(trial_tip, trial_residual, trial_position_error, trial_orientation_error);
    const S trial_cost = trial_residual.squaredNorm();
    if (trial_cost < cost_ && trial.allFinite()) {
      // Slow progress means the linearised model's own minimum is near (it
      // is not exact far from b_k): better spent on a new evaluation.
      if (trial_cost > S(0.25) * cost_) ++slow_steps_;
      bend_ = trial;
      tip_ = trial_tip;
      residual_ = trial_residual;
      cost_ = trial_cost;
      position_error_ = trial_position_error;
      orientation_error_ = trial_orientation_error;
      damping_ = std::max(damping_ * S(0.1), problem.options.min_damping);
      flow.on(Event::step_accepted);
    } else if (preferred) {
      // The preference's part of the step is projected on the linearisation
      // at this point, with the damping's leak: a step it spoilt is tried
      // again without it, at the same damping.
      flow.on(Event::preferred_step_spoilt);
      for (int i = 0; i < segments; ++i) active_[i] = active_[i] && problem.on_limit(i, bend_);
    } else {
      damping_ *= S(10);
      flow.on(Event::step_rejected);
      // A rejected step may have put segments in the active set that the
      // accepted point does not have on its limit.
      for (int i = 0; i < segments; ++i) active_[i] = active_[i] && problem.on_limit(i, bend_);
    }
  }

 private:
  void evaluate_pose(const Problem<S, Max>& problem, const Linearisation<S, Max>& lin, const SolveFlow& flow,
                     const Joints& bend, Pose<S>& tip) const {
    tip = exp(lin.eps_at(bend, flow)) * forward_kinematics_bend(bend, *problem.geometry);
  }

  // The damped step on the reduced coordinates: two per free segment, one
  // (along the limit circle) per active segment.
  template <int Rows>
  Joints step(const Problem<S, Max>& problem, const Preference<S, Max>& preference, bool preferred) const {
    const int segments = problem.geometry->segment_count;
    using Reduced = Eigen::Matrix<S, Rows, Eigen::Dynamic, Eigen::RowMajor, Rows, kMaxColumns>;
    Reduced reduced(Rows, 2 * segments);
    Vec2<S> tangent[Max];
    int columns = 0;
    for (int i = 0; i < segments; ++i) {
      const auto block = rows_.template topRows<Rows>().template middleCols<2>(2 * i);
      if (active_[i]) {
        const Vec2<S> b = bend_.template segment<2>(2 * i);
        const S theta = b.norm();
        tangent[i] = theta > S(0) ? Vec2<S>(-b.y() / theta, b.x() / theta) : Vec2<S>(S(0), S(1));
        reduced.col(columns++) = block * tangent[i];
      } else {
        reduced.template middleCols<2>(columns) = block;
        columns += 2;
      }
    }
    // Coefficient-wise products: Eigen's general product paths can fall back
    // to heap workspace, which a board build must not link.
    const auto used = reduced.leftCols(columns);
    Eigen::Matrix<S, Rows, Rows> normal = used.lazyProduct(used.transpose());
    const S scale = normal.trace() / S(problem.kind == IkTargetKind::pose ? 6 : 3);
    normal.diagonal().array() += damping_ * scale + std::numeric_limits<S>::min();
    // The pose task's step J^T (J J^T + damping)^-1 r and, with a
    // preference, that of its pull on the same factor. (One vector at a
    // time: Eigen's solve of a two-column right-hand side goes through a
    // blocked path that allocates.)
    using Step = Eigen::Matrix<S, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxColumns, 1>;
    const Eigen::LDLT<Eigen::Matrix<S, Rows, Rows>> factor = normal.ldlt();
    const Eigen::Matrix<S, Rows, 1> y = factor.solve(residual_.template head<Rows>());
    Step step = used.transpose().lazyProduct(y);
    if (preferred) {
      preference.template add_to_step<Rows>(step, used, factor, columns, bend_, active_, tangent, *problem.geometry);
    }

    Joints trial = bend_;
    columns = 0;
    for (int i = 0; i < segments; ++i) {
      if (active_[i]) {
        trial.template segment<2>(2 * i) += step[columns++] * tangent[i];
      } else {
        trial.template segment<2>(2 * i) += step.template segment<2>(columns);
        columns += 2;
      }
    }
    return trial;
  }

  Joints bend_;
  Pose<S> tip_{};
  Residual residual_ = Residual::Zero();
  S cost_ = S(0);
  S position_error_ = S(0);
  S orientation_error_ = S(0);
  S position_goal_ = S(0);
  S orientation_goal_ = S(0);
  S damping_ = S(1e-4);
  int iterations_ = 0;
  int slow_steps_ = 0;
  // The segments held on their limit circle (the active set).
  bool active_[Max] = {};
  Eigen::Matrix<S, 6, kMaxColumns, Eigen::RowMajor> rows_ = Eigen::Matrix<S, 6, kMaxColumns, Eigen::RowMajor>::Zero();
};

}  // namespace cdcr::model::ik
