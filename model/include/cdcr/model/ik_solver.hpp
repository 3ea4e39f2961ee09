#pragma once
// Inverse kinematics as a resumable solver: a target pose (or position) to
// joint variables, in slices of bounded work, with the whole state inside
// the object so that it can live in static memory and continue over as many
// fixed-rate cycles as a solve needs.
//
// Method: a fixed point on the corrected target, accelerated by secant
// updates of the correction's slope.
//   * The compensated model is T_c(b) = exp(eps(b)) T(b): nominal kinematics
//     T and a correction eps (the GP mean of the tip error twist) of the bend
//     vector b. eps is the expensive part: one evaluation is a pass over
//     every training point. Its analytic gradient costs several passes more.
//   * Each outer iteration evaluates eps once, at the current point b_k
//     (sliced: an evaluation may span several cycles), and checks the
//     compensated residual there: that is the convergence test, on the exact
//     model.
//   * Between evaluations, a damped least-squares (Levenberg-Marquardt)
//     iteration solves the cheap linearised model
//         exp(eps_k + E (b - b_k)) T(b) = target
//     with the analytic nominal Jacobian. E (6 x D) is the correction's
//     slope: its analytic gradient where one was evaluated, updated by
//     Broyden's secant rule from the evaluations made since. With E = 0 this
//     is the plain fixed point b = IK_nominal(exp(-eps_k) target).
//   * The gradient costs a few mean evaluations (kGradientPointUnits per
//     training point for the GP), so it is evaluated only where the slope is
//     unknown (a cold start) or where the last outer iteration contracted
//     the residual poorly (the secant slope has gone stale); the next
//     evaluation then computes the mean and the gradient in one pass.
//   * E survives from one target to the next, so a target streamed along a
//     path starts with the slope known and usually needs one mean evaluation.
//   * A streamed target (retarget()) gets one damped step first thing in the
//     next run(), on the linearisation and the rows in hand, while the
//     evaluation at a newer point goes on in the rest of the budget (it runs
//     at evaluation_point_; the linearisation point_ changes only when it
//     ends). So the linearised point follows the stream every call, and the
//     exact model catches up every few.
//   * Within keep_damping_within_mm of the target the LM damping carries over
//     between outer iterations: the weakly actuated twist about the backbone
//     of a pose target converges at the rate the damping allows.
//   * The limit theta_i <= theta_max is a disc in each segment's bend plane.
//     A segment that a step would carry outside joins the active set: it then
//     moves only along the limit circle (one tangential coordinate), and it
//     leaves the set when the cost's descent direction points back inside.
//     Steps are never projected, so a solution on the limit is reached at the
//     LM rate instead of crawling along the boundary.
//   * A start that stalls (the outer residual stops decreasing, or the LM
//     damping blows up away from the target) is restarted from the next
//     start in a fixed list, up to a bound.
//
// Work is counted in units: one unit is one training point of a correction
// evaluation; a nominal LM iteration and the outer bookkeeping cost the
// fixed number of units in IkWorkCosts. run(budget) does whole steps while
// their cost fits in what is left of the budget and returns what it spent, so
// a caller bounds a cycle's IK work by the budget it passes.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>

#include <Eigen/Cholesky>

#include "cdcr/model/chain.hpp"
#include "cdcr/model/geometry.hpp"
#include "cdcr/model/ik/correction_evaluation.hpp"
#include "cdcr/model/ik/options.hpp"
#include "cdcr/model/se3.hpp"
#include "cdcr/model/status.hpp"
#include "cdcr/model/types.hpp"
#include "cdcr/model/work_costs.hpp"

namespace cdcr::model {

template <typename S, int Max, typename Correction = NoCorrection>
class IkSolver {
  static constexpr bool kSliced = is_sliced_correction<Correction>::value;
  using Evaluator = std::conditional_t<kSliced, Correction, detail::WholeEvaluation<S, Max, Correction>>;

 public:
  using Joints = JointVector<S, Max>;
  using Residual = Eigen::Matrix<S, 6, 1>;
  static constexpr int kMaxColumns = 2 * Max;
  // Secant steps shorter than this (rad of bend) are not learned from.
  static constexpr S kMinSecantStep = std::is_same_v<S, float> ? S(1e-4) : S(1e-8);
  // Joints this close to the last best point (rad of bend) start from it:
  // the setpoints' joints are its (alpha, theta), which round-trip the bend
  // to a few float steps.
  static constexpr S kSameBendRad = std::is_same_v<S, float> ? S(1e-5) : S(1e-12);

  IkSolver() = default;
  IkSolver(const IkSolver&) = delete;
  IkSolver& operator=(const IkSolver&) = delete;

  // Binds the geometry and the correction (both must outlive the solver) and
  // forgets every target and the learned slope.
  void configure(const RobotGeometry<S, Max>& geometry, const Correction& correction,
                 const IkSolverOptions<S>& options = {}, const IkWorkCosts& costs = {}) {
    configure(geometry, &correction, options, costs);
  }
  // Without a correction (nullptr) the solver solves the nominal model: a
  // runtime without a valid image needs no second solver type for that.
  void configure(const RobotGeometry<S, Max>& geometry, const Correction* correction,
                 const IkSolverOptions<S>& options = {}, const IkWorkCosts& costs = {}) {
    geometry_ = &geometry;
    if (correction == nullptr) {
      evaluator_ = nullptr;
    } else if constexpr (kSliced) {
      evaluator_ = correction;
    } else {
      whole_.correction = correction;
      evaluator_ = &whole_;
    }
    options_ = options;
    costs_ = costs;
    weight_ = options.orientation_weight_mm_per_rad;
    if (!(weight_ > S(0))) {
      weight_ = S(0);
      for (int i = 0; i < geometry.segment_count; ++i) weight_ += geometry.segments[i].backbone_length_mm;
      weight_ /= S(geometry.segment_count);
    }
    state_ = IkSolveState::idle;
    slope_known_ = false;
    have_warm_start_ = false;
    linearised_ = rows_valid_ = false;
    preference_ = IkPreference<S, Max>{};
  }

  // Where to prefer solutions (IkPreference); off until set, and again after
  // configure(). Takes effect from the next step.
  void set_preference(const IkPreference<S, Max>& preference) {
    preference_ = preference;
    if (geometry_ == nullptr || !(preference_.gain > S(0)) || preference_.centre.size() != 2 * geometry_->segment_count ||
        preference_.weight.size() != 2 * geometry_->segment_count || !preference_.centre.allFinite() ||
        !preference_.weight.allFinite()) {
      preference_.gain = S(0);
    }
  }

  // Starts a solve, abandoning any running one, from initial_joints ((alpha,
  // theta) pairs within the limits) with no knowledge of the correction.
  Status start(const Pose<S>& target, IkTargetKind kind, const Joints& initial_joints) {
    if (const Status s = reset(target, kind); s != Status::ok) return s;
    linearised_ = rows_valid_ = false;
    if (const Status s = check_joints(initial_joints, *geometry_); s != Status::ok) return fail(s);
    slope_known_ = false;
    const Joints bend = bend_from_joints(initial_joints);
    best_bend_ = bend;
    state_ = IkSolveState::running;
    begin_outer(bend);
    return status_;
  }

  // Starts a solve from the best point of the previous one (a target near
  // the last, as along a streamed path): the correction there is known, and
  // the slope learned so far is kept. Without a previous point, as start().
  Status start_warm(const Pose<S>& target, IkTargetKind kind, const Joints& fallback_joints) {
    if (!have_warm_start_ || warm_bend_.size() != 2 * geometry_->segment_count) {
      return start(target, kind, fallback_joints);
    }
    if (const Status s = reset(target, kind); s != Status::ok) return s;
    best_bend_ = warm_bend_;
    point_ = warm_bend_;
    point_eps_ = warm_eps_;
    point_has_gradient_ = false;
    state_ = IkSolveState::running;
    phase_ = Phase::outer_step;
    return status_;
  }

  // Starts a solve from initial_joints; when they are the best point of the
  // previous solve (a target started from the setpoints the last one left),
  // as start_warm(): the correction there is known, which saves the first
  // evaluation, and the next evaluation brings the gradient (the last
  // target's slope alone took the M7's p99 from 53 to 56 cycles). In the
  // QEMU workload, paper-workspace pose targets' latency p50/p99: M7 24/53
  // -> 21/54, M4F 18/44 -> 15/37.
  Status start_near(const Pose<S>& target, IkTargetKind kind, const Joints& initial_joints) {
    if (have_warm_start_ && geometry_ != nullptr && initial_joints.size() == warm_bend_.size() &&
        initial_joints.allFinite() &&
        (bend_from_joints(initial_joints) - warm_bend_).cwiseAbs().maxCoeff() <= kSameBendRad) {
      const Status s = start_warm(target, kind, initial_joints);
      gradient_with_next_evaluation_ = true;
      return s;
    }
    return start(target, kind, initial_joints);
  }

  // Moves the target of a running solve (a stream of targets along a path):
  // the work in progress is kept, since a correction evaluation does not
  // depend on the target; the best point is re-scored against the new
  // target, and the bounds count afresh. Not running: as start_warm().
  Status retarget(const Pose<S>& target, IkTargetKind kind, const Joints& fallback_joints) {
    if (state_ != IkSolveState::running) return start_warm(target, kind, fallback_joints);
    if (!target.all_finite()) return fail(Status::non_finite_input);
    const IkTargetKind previous_kind = kind_;
    target_ = target;
    kind_ = kind;
    corrections_ = 0;
    iterations_ = 0;
    restarts_ = 0;
    units_spent_ = 0;
    stalled_outer_ = 0;
    // The secant pair stays (the correction does not depend on the target);
    // the last residual, measured against the old target, does not count.
    previous_cost_ = std::numeric_limits<S>::infinity();
    if (have_warm_start_) {
      // The best point's tip was kept: only its residual is new.
      Residual residual;
      residual_of(warm_tip_, residual, best_position_error_, best_orientation_error_);
      best_cost_ = residual.squaredNorm();
      best_bend_ = warm_bend_;
    } else {
      best_cost_ = std::numeric_limits<S>::infinity();
      best_position_error_ = best_orientation_error_ = std::numeric_limits<S>::infinity();
    }
    if (kind != previous_kind) rows_current_ = rows_valid_ = false;
    if (linearised_) {
      // The linearised model and its Jacobian do not depend on the target
      // either: the solve on it goes on towards the new one, with a step
      // first thing in the next run().
      residual_of(inner_tip_, inner_residual_, inner_position_error_, inner_orientation_error_);
      inner_cost_ = inner_residual_.squaredNorm();
      track_pending_ = true;
      // Its iteration bounds and damping carry on: a target that moves every
      // cycle must not keep the solve from ever reaching the next evaluation,
      // nor hold the damping where it hides the weakly actuated directions.
      if (phase_ == Phase::inner && inner_done()) finish_inner();
    }
    return status_;
  }

  // Does whole steps while their cost fits in `budget` units; returns the
  // units spent (0 when nothing fits or nothing is left to do). A correction
  // evaluation is sliced to fit; a nominal iteration runs only when its whole
  // cost fits.
  std::uint32_t run(std::uint32_t budget) {
    std::uint32_t spent = 0;
    if (track_pending_ && state_ == IkSolveState::running) {
      // A streamed target's step comes first, on the linearisation and the
      // rows at hand (a Jacobian from a step or two back does for a target
      // a fraction of a millimetre on): the setpoints follow the stream
      // every cycle while evaluations and Jacobians go on in the rest.
      track_pending_ = false;
      if (linearised_ && rows_valid_) spent = track_step(budget);
    }
    while (state_ == IkSolveState::running) {
      const std::uint32_t left = budget - spent;
      if (phase_ == Phase::evaluate && linearised_ && stale_row_steps_ >= kMaxStaleRowSteps &&
          left >= costs_.nominal_jacobian) {
        // Streamed steps have gone on on old rows for a while: new ones at
        // the current point, before the evaluation's next slice.
        spent += costs_.nominal_jacobian;
        update_rows();
        continue;
      }
      if (phase_ == Phase::evaluate) {
        if (left == 0) break;
        const std::uint32_t used = continue_correction(left);
        spent += used;
        if (state_ != IkSolveState::running) break;
        if (!evaluator_->evaluation_finished(evaluation_)) {
          if (used == 0) break;  // the next slice does not fit
          continue;
        }
        point_ = evaluation_point_;
        point_has_gradient_ = evaluator_->evaluation_has_gradient(evaluation_);
        evaluator_->evaluation_result(evaluation_, point_eps_, point_gradient_);
        ++corrections_;
        phase_ = Phase::outer_step;
        continue;
      }
      if (phase_ == Phase::outer_step) {
        if (left < costs_.outer_step) break;
        spent += costs_.outer_step;
        outer_step();
        continue;
      }
      // Phase::inner
      if (!rows_current_) {
        if (left < costs_.nominal_jacobian) break;
        spent += costs_.nominal_jacobian;
        update_rows();
        continue;
      }
      if (left < costs_.nominal_step) break;
      spent += costs_.nominal_step;
      inner_iteration();
    }
    units_spent_ += spent;
    return spent;
  }

  // Runs to the end with no budget: for callers off the fixed-rate cycle.
  IkSolveState run_to_end() {
    while (state_ == IkSolveState::running) run(std::numeric_limits<std::uint32_t>::max() / 2);
    return state_;
  }

  IkSolveState state() const { return state_; }
  Status status() const { return status_; }
  IkTargetKind kind() const { return kind_; }
  const Pose<S>& target() const { return target_; }
  // Correction evaluations and nominal LM iterations spent on this target.
  int corrections() const { return corrections_; }
  int iterations() const { return iterations_; }
  int restarts() const { return restarts_; }
  // Units run() has spent on this target.
  std::uint64_t units_spent() const { return units_spent_; }
  bool has_best() const { return best_cost_ < std::numeric_limits<S>::infinity(); }
  // The best point whose compensated residual has been evaluated exactly,
  // as (alpha, theta) pairs, and its residual.
  Joints best_joints() const { return clamped_joints(best_bend_); }
  S best_position_error_mm() const { return best_position_error_; }
  // The linearised solve's current point, while one runs: its correction is
  // predicted from the last evaluation and the slope, not evaluated, so it is
  // for following a stream of targets between evaluations.
  bool has_linearised_point() const { return state_ == IkSolveState::running && linearised_; }
  const Joints& linearised_bend() const { return inner_bend_; }
  Joints linearised_joints() const { return clamped_joints(inner_bend_); }
  S linearised_position_error_mm() const { return inner_position_error_; }
  S linearised_orientation_error_rad() const { return inner_orientation_error_; }
  const Joints& best_bend() const { return best_bend_; }
  S best_orientation_error_rad() const { return best_orientation_error_; }

 private:
  enum class Phase : std::uint8_t { evaluate, outer_step, inner };

  Joints clamped_joints(const Joints& bend) const {
    Joints joints = joints_from_bend(bend);
    for (int i = 0; i < geometry_->segment_count; ++i) {
      // A point on the limit circle can sit one rounding step outside it.
      joints[2 * i + 1] = std::min(joints[2 * i + 1], geometry_->segments[i].theta_max_rad);
    }
    return joints;
  }

  // Residual of the target against a tip pose: position (mm) and, for pose
  // targets, the weighted rotation vector of R_target R^T.
  void residual_of(const Pose<S>& tip, Residual& residual, S& position_error, S& orientation_error) const {
    const Vec3<S> dp = target_.position_mm - tip.position_mm;
    position_error = dp.norm();
    residual.template head<3>() = dp;
    if (kind_ == IkTargetKind::pose) {
      const Vec3<S> dr = log_so3<S>(Mat3<S>(target_.rotation * tip.rotation.transpose()));
      orientation_error = dr.norm();
      residual.template tail<3>() = weight_ * dr;
    } else {
      orientation_error = S(0);
      residual.template tail<3>().setZero();
    }
  }

  bool within_tolerance(S position_error, S orientation_error) const {
    return position_error <= options_.position_tolerance_mm && orientation_error <= options_.orientation_tolerance_rad;
  }

  Status reset(const Pose<S>& target, IkTargetKind kind) {
    state_ = IkSolveState::failed;
    status_ = Status::ok;
    corrections_ = 0;
    iterations_ = 0;
    restarts_ = 0;
    units_spent_ = 0;
    have_previous_ = false;
    next_with_gradient_ = false;
    gradient_with_next_evaluation_ = false;
    stalled_outer_ = 0;
    have_damping_ = false;
    track_pending_ = false;
    tracked_since_outer_ = false;
    prefer_in_step_ = true;
    best_cost_ = std::numeric_limits<S>::infinity();
    best_position_error_ = best_orientation_error_ = std::numeric_limits<S>::infinity();
    if (geometry_ == nullptr) return status_ = Status::invalid_geometry;
    if (!target.all_finite()) return fail(Status::non_finite_input);
    target_ = target;
    kind_ = kind;
    return Status::ok;
  }

  bool wants_gradient() const {
    if (!(options_.gradient_refresh_ratio > S(0))) return false;
    if constexpr (!kSliced) {
      if (!detail::WholeEvaluation<S, Max, Correction>::kHasGradient) return false;
    }
    return !slope_known_ || next_with_gradient_;
  }

  void begin_outer(const Joints& bend) {
    tracked_since_outer_ = false;
    if (evaluator_ == nullptr) {
      // The nominal model: the correction and its slope are zero.
      point_ = bend;
      point_eps_.setZero();
      point_gradient_.setZero(6, point_.size());
      point_has_gradient_ = true;
      ++corrections_;
      phase_ = Phase::outer_step;
      return;
    }
    // The linearisation in use (point_) stays until this evaluation ends: a
    // streamed target's steps go on on it meanwhile.
    evaluation_point_ = bend;
    if (const Status s = evaluator_->begin_evaluation(evaluation_point_, evaluation_, wants_gradient());
        s != Status::ok) {
      fail(s);
      return;
    }
    phase_ = Phase::evaluate;
  }

  std::uint32_t continue_correction(std::uint32_t max_units) {
    if constexpr (kSliced) {
      return evaluator_->continue_evaluation(evaluation_, max_units);
    } else {
      (void)max_units;
      if (const Status s = whole_.finish(evaluation_); s != Status::ok) fail(s);
      return 1;
    }
  }

  // The correction at point_ is known: test convergence on the compensated
  // model, learn the slope, and set up the next linearised solve.
  void outer_step() {
    if (!point_eps_.allFinite()) {
      fail(Status::correction_failed);
      return;
    }

    const Pose<S> tip = exp(point_eps_) * forward_kinematics_bend(point_, *geometry_);
    Residual residual;
    S position_error = S(0);
    S orientation_error = S(0);
    residual_of(tip, residual, position_error, orientation_error);
    const S cost = residual.squaredNorm();

    if (point_has_gradient_) {
      slope_ = point_gradient_;
      slope_known_ = slope_.allFinite();
    } else if (options_.secant_updates && have_previous_) {
      // Secant update of the slope from the last outer point to this one;
      // steps below the arithmetic's resolution carry only noise.
      const Joints step = point_ - previous_point_;
      const S step_sq = step.squaredNorm();
      if (step_sq > kMinSecantStep * kMinSecantStep) {
        if (!slope_known_) {
          slope_.setZero(6, point_.size());
          slope_known_ = true;
        }
        const Twist<S> predicted = previous_eps_ + slope_.lazyProduct(step);
        slope_.noalias() += ((point_eps_ - predicted) / step_sq).lazyProduct(step.transpose());
        if (!slope_.allFinite()) slope_known_ = false;
      }
    }

    if (cost < best_cost_) {
      best_cost_ = cost;
      best_bend_ = point_;
      best_position_error_ = position_error;
      best_orientation_error_ = orientation_error;
      // The next target may start here with the correction known.
      warm_bend_ = point_;
      warm_eps_ = point_eps_;
      warm_tip_ = tip;
      have_warm_start_ = true;
    }
    if (within_tolerance(position_error, orientation_error)) {
      state_ = IkSolveState::converged;
      return;
    }
    // A start stalls when the exact residual stops decreasing clearly.
    if (have_previous_ && !(cost < S(0.9) * previous_cost_)) {
      ++stalled_outer_;
    } else {
      stalled_outer_ = 0;
    }
    if (corrections_ >= options_.max_corrections || iterations_ >= options_.max_iterations) {
      state_ = IkSolveState::not_converged;
      return;
    }
    // Near the tolerance a stall is the arithmetic's floor, not a bad start,
    // but it takes a third stalled iteration to say so. Near the straight robot
    // the tip's travel along the backbone and its roll about it are weakly
    // actuated: a few mm/rad of nominal gain, no more than a trained
    // correction's slope, so a secant slope a little off, and the float
    // correction's own scatter (about 1 um: two summation orders of the
    // demo model differ by that), let the residual wander at 2-3 um against
    // a 2 um tolerance (2.1 -> 2.5 -> 3.5 um in a row). Two stalls ended
    // such solves a few um short; the third iteration, one more correction
    // evaluation, mostly lands inside (the demo model's own poses from the
    // straight start, tools/bench/ik_convergence_bench.cpp: 199 of 200 near
    // straight and 199 of 200 in the paper's workspace, 191 and 191 with
    // two). A gradient refresh near the floor as well gave the same counts
    // for more cycles. The stalls that end far from the target are another
    // matter: the demo circle's start (a pose of the simulated robot) lies
    // 86 um outside the compensated model's image near the straight robot
    // (the tip cannot rise that far along the backbone at that bend and
    // orientation; 300 random starts end no closer), which no step fixes.
    // Only within a few tolerances of the target: farther out a third
    // evaluation only costs cycles (the runtime accepts such a residual).
    const bool at_floor = position_error <= S(20) * options_.position_tolerance_mm;
    const bool wandering_at_tolerance = position_error <= S(3) * options_.position_tolerance_mm;
    if (stalled_outer_ >= (wandering_at_tolerance ? 3 : 2)) {
      if (at_floor || !restart()) state_ = IkSolveState::not_converged;
      return;
    }
    // A stale slope shows as poor contraction: evaluate the gradient with
    // the next mean.
    // Near the tolerance the contraction is limited by the arithmetic, which
    // a gradient does not improve.
    // A stream's steps (tracked_since_outer_) lean on the slope the most:
    // between evaluations they go on on the linearised correction, and a
    // secant slope a little off took the demo circle's following error to
    // 0.086 mm for a few cycles after an evaluation landed. With the
    // gradient in every evaluation of a stream (each then takes about three
    // times the units, so the linearisation is a cycle or two older):
    // 0.013 mm at worst, 0.005 mm mean (0.007 before).
    next_with_gradient_ = tracked_since_outer_ || gradient_with_next_evaluation_ ||
                          (have_previous_ && cost > options_.gradient_refresh_ratio * previous_cost_ &&
                           position_error > S(20) * options_.position_tolerance_mm);
    gradient_with_next_evaluation_ = false;
    previous_point_ = point_;
    previous_eps_ = point_eps_;
    previous_cost_ = cost;
    have_previous_ = true;

    // The linearised solve starts where the exact model was just evaluated,
    // or where a streamed target's steps have taken it since.
    if (!tracked_since_outer_) inner_bend_ = point_;
    linearised_ = true;
    inner_iterations_ = 0;
    inner_slow_steps_ = 0;
    if (!have_damping_ || position_error > options_.keep_damping_within_mm) damping_ = options_.initial_damping;
    have_damping_ = true;
    for (int i = 0; i < geometry_->segment_count; ++i) active_[i] = on_limit(i, inner_bend_);
    evaluate_inner_pose(inner_bend_, inner_tip_);
    residual_of(inner_tip_, inner_residual_, inner_position_error_, inner_orientation_error_);
    inner_cost_ = inner_residual_.squaredNorm();
    rows_current_ = false;
    if constexpr (kSliced) {
      // Inexact solves: far from the target, the linearised model need not
      // be solved much beyond the accuracy the next evaluation will show.
      inner_position_goal_ = std::max(S(0.5) * options_.position_tolerance_mm, S(0.02) * position_error);
      inner_orientation_goal_ = std::max(S(0.5) * options_.orientation_tolerance_rad, S(0.02) * orientation_error);
    } else {
      // An evaluation in one call is cheap: solve to the tolerance.
      inner_position_goal_ = options_.position_tolerance_mm;
      inner_orientation_goal_ = options_.orientation_tolerance_rad;
    }
    phase_ = Phase::inner;
    if (inner_done()) finish_inner();
  }

  // A new start after a stall, from a fixed list: the straight robot with a
  // slight bend, then bends turned a quarter and a half turn.
  bool restart() {
    if (restarts_ >= options_.max_restarts) return false;
    ++restarts_;
    Joints joints(2 * geometry_->segment_count);
    static constexpr S kPhase[] = {S(0), S(1.5707963), S(3.1415927), S(-1.5707963)};
    for (int i = 0; i < geometry_->segment_count; ++i) {
      joints[2 * i] = kPhase[(restarts_ + i) % 4];
      joints[2 * i + 1] = std::min(S(0.1) * S(restarts_), geometry_->segments[i].theta_max_rad);
    }
    have_previous_ = false;
    stalled_outer_ = 0;
    slope_known_ = false;
    begin_outer(bend_from_joints(joints));
    return true;
  }

  Status fail(Status status) {
    status_ = status;
    state_ = IkSolveState::failed;
    return status;
  }

  bool on_limit(int segment, const Joints& bend) const {
    const S theta = bend.template segment<2>(2 * segment).norm();
    return theta >= geometry_->segments[segment].theta_max_rad * (S(1) - S(16) * std::numeric_limits<S>::epsilon());
  }

  // A streamed target's step on the linearisation in hand; returns the
  // units spent. New rows when the slice also holds the step (and an outer
  // step waiting for its turn: a cycle whose new rows crowded out the step
  // sent the last target's point again), or when the
  // old ones have served long enough (that cycle's step then waits a
  // cycle). An outer step waiting for its turn goes first when the slice
  // cannot hold both: the stream's steps must not starve the evaluations.
  std::uint32_t track_step(std::uint32_t budget) {
    std::uint32_t spent = 0;
    const std::uint32_t waiting = phase_ == Phase::outer_step ? costs_.outer_step : 0;
    const bool renew_rows = !rows_current_ && (budget >= costs_.nominal_jacobian + costs_.nominal_step + waiting ||
                                               stale_row_steps_ >= kMaxStaleRowSteps);
    if (renew_rows && budget >= costs_.nominal_jacobian) {
      spent += costs_.nominal_jacobian;
      update_rows();
    }
    if (budget - spent < costs_.nominal_step + waiting) return spent;
    spent += costs_.nominal_step;
    // The stream's steps are the pose task's alone: a target that moves
    // every cycle is followed most closely by the smallest motion (the
    // preference's drift on the demo's circle took the following error's
    // maximum from 0.086 to 0.150 mm); the preference acts in the
    // iterations between.
    if (phase_ == Phase::inner) {
      inner_iteration(false);
    } else {
      ++iterations_;
      try_inner_step<6>(false);
      tracked_since_outer_ = true;
    }
    if (!rows_current_) ++stale_row_steps_;
    return spent;
  }

  // The linearised compensated model: exp(eps_k + E (b - b_k)) T(b).
  Twist<S> linearised_eps(const Joints& bend) const {
    Twist<S> eps = point_eps_;
    if (slope_known_) eps.noalias() += slope_.lazyProduct(bend - point_);
    return eps;
  }

  void evaluate_inner_pose(const Joints& bend, Pose<S>& tip) const {
    tip = exp(linearised_eps(bend)) * forward_kinematics_bend(bend, *geometry_);
  }

  bool inner_done() const {
    return inner_position_error_ <= inner_position_goal_ && inner_orientation_error_ <= inner_orientation_goal_;
  }

  void finish_inner() { begin_outer(inner_bend_); }

  // One LM iteration on the linearised model.
  // Position targets use the same six rows with the orientation rows and
  // residual zero: the damped step is then the three-row one, and the
  // firmware carries one copy of the code.
  void update_rows() { update_rows_of<6>(); }
  void inner_iteration(bool may_prefer = true) { inner_iteration_rows<6>(may_prefer); }

  // The linearised model's Jacobian at inner_bend_, as residual rows.
  template <int Rows>
  void update_rows_of() {
    const int segments = geometry_->segment_count;
    Pose<S> tip;
    Jacobian<S, Max> spatial;
    tip_jacobian_bend(inner_bend_, *geometry_, tip, spatial);
    const Twist<S> eps = linearised_eps(inner_bend_);
    const Pose<S> correction_pose = exp(eps);
    apply_adjoint(correction_pose, spatial);
    if (slope_known_) spatial.noalias() += left_jacobian(eps).lazyProduct(slope_);
    tip = correction_pose * tip;
    rows_.setZero();
    rows_.template topLeftCorner<3, kMaxColumns>().leftCols(2 * segments) =
        spatial.template topRows<3>() - hat3<S>(tip.position_mm) * spatial.template bottomRows<3>();
    if (kind_ == IkTargetKind::pose) {
      rows_.template bottomLeftCorner<3, kMaxColumns>().leftCols(2 * segments) =
          weight_ * spatial.template bottomRows<3>();
    }
    rows_current_ = rows_valid_ = true;
    stale_row_steps_ = 0;
    // Segments on the limit leave the active set when descent points inside.
    for (int i = 0; i < segments; ++i) {
      if (!active_[i]) continue;
      const Vec2<S> b = inner_bend_.template segment<2>(2 * i);
      const Vec2<S> descent = rows_.template topRows<Rows>().template middleCols<2>(2 * i).transpose() *
                              inner_residual_.template head<Rows>();
      if (b.dot(descent) < S(0)) active_[i] = false;
    }
  }

  // One LM iteration of the linearised solve: the damped step, then whether
  // the solve restarts, goes on, or hands over to the next evaluation.
  template <int Rows>
  void inner_iteration_rows(bool may_prefer) {
    ++iterations_;
    ++inner_iterations_;
    try_inner_step<Rows>(may_prefer);

    const bool stalled = damping_ > S(1e8);
    if (stalled && inner_bend_ == point_ && inner_position_error_ > options_.restart_above_mm) {
      // No step helps at all: a local minimum of the model far from the target.
      if (!restart()) state_ = IkSolveState::not_converged;
      return;
    }
    const bool give_up_inner =
        kSliced && (inner_slow_steps_ >= 2 || inner_iterations_ >= options_.max_inner_iterations);
    if (inner_done() || stalled || give_up_inner ||
        iterations_ >= options_.max_iterations) {
      finish_inner();
    }
  }

  // The damped step from inner_bend_ on the current rows, kept when the
  // linearised model's cost falls; the damping adapts either way.
  template <int Rows>
  void try_inner_step(bool may_prefer) {
    const int segments = geometry_->segment_count;
    Joints trial;
    bool stepped = false;
    // Within 20 tolerances of the target (where a stall counts as the
    // arithmetic's floor) the steps are the pose task's alone: the
    // preference's drift, however small, spoilt the secant slope the last
    // few um need (in-range targets of the IK bench: 194 of 200 converged
    // with the preference to the end, 197 without it there; the
    // solutions' spread is the same).
    const bool preferred = may_prefer && prefer_in_step_ && preference_.gain > S(0) &&
                           inner_position_error_ > S(20) * options_.position_tolerance_mm;
    // Each pass may add segments to the active set; at most one pass per segment.
    for (int pass = 0; pass <= segments && !stepped; ++pass) {
      trial = inner_step<Rows>(preferred);
      stepped = true;
      for (int i = 0; i < segments; ++i) {
        if (active_[i]) continue;
        const S theta = trial.template segment<2>(2 * i).norm();
        if (theta > geometry_->segments[i].theta_max_rad) {
          active_[i] = true;
          stepped = false;
        }
      }
    }
    // Whatever is left outside (all passes used) goes back onto the circle.
    for (int i = 0; i < segments; ++i) {
      const S theta = trial.template segment<2>(2 * i).norm();
      const S limit = geometry_->segments[i].theta_max_rad;
      if ((active_[i] || theta > limit) && theta > S(0)) trial.template segment<2>(2 * i) *= limit / theta;
    }

    Pose<S> trial_tip;
    evaluate_inner_pose(trial, trial_tip);
    Residual trial_residual;
    S trial_position_error = S(0);
    S trial_orientation_error = S(0);
    residual_of(trial_tip, trial_residual, trial_position_error, trial_orientation_error);
    const S trial_cost = trial_residual.squaredNorm();
    if (trial_cost < inner_cost_ && trial.allFinite()) {
      // Slow progress means the linearised model's own minimum is near (it
      // is not exact far from b_k): better spent on a new evaluation.
      if (trial_cost > S(0.25) * inner_cost_) ++inner_slow_steps_;
      inner_bend_ = trial;
      inner_tip_ = trial_tip;
      inner_residual_ = trial_residual;
      inner_cost_ = trial_cost;
      inner_position_error_ = trial_position_error;
      inner_orientation_error_ = trial_orientation_error;
      rows_current_ = false;
      damping_ = std::max(damping_ * S(0.1), options_.min_damping);
      prefer_in_step_ = true;
    } else if (preferred) {
      // The preference's part of the step is projected on the linearisation
      // at this point, with the damping's leak: a step it spoilt is tried
      // again without it, at the same damping.
      prefer_in_step_ = false;
      for (int i = 0; i < segments; ++i) active_[i] = active_[i] && on_limit(i, inner_bend_);
    } else {
      damping_ *= S(10);
      prefer_in_step_ = true;
      // A rejected step may have put segments in the active set that the
      // accepted point does not have on its limit.
      for (int i = 0; i < segments; ++i) active_[i] = active_[i] && on_limit(i, inner_bend_);
    }
  }

  // The damped step on the reduced coordinates: two per free segment, one
  // (along the limit circle) per active segment.
  template <int Rows>
  Joints inner_step(bool preferred) const {
    const int segments = geometry_->segment_count;
    using Reduced = Eigen::Matrix<S, Rows, Eigen::Dynamic, Eigen::RowMajor, Rows, kMaxColumns>;
    Reduced reduced(Rows, 2 * segments);
    Vec2<S> tangent[Max];
    int columns = 0;
    for (int i = 0; i < segments; ++i) {
      const auto block = rows_.template topRows<Rows>().template middleCols<2>(2 * i);
      if (active_[i]) {
        const Vec2<S> b = inner_bend_.template segment<2>(2 * i);
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
    const S scale = normal.trace() / S(kind_ == IkTargetKind::pose ? 6 : 3);
    normal.diagonal().array() += damping_ * scale + std::numeric_limits<S>::min();
    // The pose task's step J^T (J J^T + damping)^-1 r and, with a
    // preference, that of its pull z on the same factor: z less what the
    // pose task sees of it, z - J^T (J J^T + damping)^-1 J z. (One vector
    // at a time: Eigen's solve of a two-column right-hand side goes
    // through a blocked path that allocates.)
    using Step = Eigen::Matrix<S, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxColumns, 1>;
    const Eigen::LDLT<Eigen::Matrix<S, Rows, Rows>> factor = normal.ldlt();
    const Eigen::Matrix<S, Rows, 1> y = factor.solve(inner_residual_.template head<Rows>());
    Step step = used.transpose().lazyProduct(y);
    if (preferred) {
      Step z(columns);
      columns = 0;
      for (int i = 0; i < segments; ++i) {
        const Vec2<S> b = inner_bend_.template segment<2>(2 * i);
        Vec2<S> pull = preference_.weight.template segment<2>(2 * i).cwiseProduct(
            preference_.centre.template segment<2>(2 * i) - b);
        const S theta = b.norm();
        const S keep_within = (S(1) - preference_.limit_margin) * geometry_->segments[i].theta_max_rad;
        if (theta > keep_within) pull -= ((theta - keep_within) / theta) * b;
        pull *= preference_.gain;
        if (active_[i]) {
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
      // steps before a solution are left alone (in the IK bench, with no cap
      // the paper workspace's targets took 24 cycles at p50 against 21
      // without the preference; capped, 20).
      const S longest = step.norm();
      const S length = null_step.norm();
      if (length > longest) null_step *= longest / length;
      step += null_step;
    }

    Joints trial = inner_bend_;
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

  const RobotGeometry<S, Max>* geometry_ = nullptr;
  const Evaluator* evaluator_ = nullptr;
  detail::WholeEvaluation<S, Max, Correction> whole_{};
  IkSolverOptions<S> options_{};
  IkWorkCosts costs_{};
  S weight_ = S(1);

  IkSolveState state_ = IkSolveState::idle;
  Status status_ = Status::ok;
  Phase phase_ = Phase::evaluate;
  Pose<S> target_{};
  IkTargetKind kind_ = IkTargetKind::pose;
  int corrections_ = 0;
  int iterations_ = 0;
  int restarts_ = 0;
  std::uint64_t units_spent_ = 0;

  // The outer iteration: the point where the exact correction is (being)
  // evaluated, the previous one, and the learned slope.
  typename Evaluator::Evaluation evaluation_{};
  Joints point_;
  Joints evaluation_point_;
  // point_ holds an evaluated correction (the linearisation in use).
  bool linearised_ = false;
  Twist<S> point_eps_ = Twist<S>::Zero();
  Jacobian<S, Max> point_gradient_;
  bool point_has_gradient_ = false;
  bool next_with_gradient_ = false;
  // start_near(): the slope is the last target's; the next evaluation
  // brings this one's.
  bool gradient_with_next_evaluation_ = false;
  Joints previous_point_;
  Twist<S> previous_eps_ = Twist<S>::Zero();
  S previous_cost_ = S(0);
  bool have_previous_ = false;
  int stalled_outer_ = 0;
  Jacobian<S, Max> slope_;
  bool slope_known_ = false;
  Joints warm_bend_;
  Twist<S> warm_eps_ = Twist<S>::Zero();
  Pose<S> warm_tip_{};
  bool have_warm_start_ = false;

  Joints best_bend_;
  S best_cost_ = std::numeric_limits<S>::infinity();
  S best_position_error_ = std::numeric_limits<S>::infinity();
  S best_orientation_error_ = std::numeric_limits<S>::infinity();

  // The linearised solve between two evaluations.
  Joints inner_bend_;
  Pose<S> inner_tip_{};
  Residual inner_residual_ = Residual::Zero();
  S inner_cost_ = S(0);
  S inner_position_error_ = S(0);
  S inner_orientation_error_ = S(0);
  S inner_position_goal_ = S(0);
  S inner_orientation_goal_ = S(0);
  S damping_ = S(1e-4);
  bool have_damping_ = false;
  int inner_iterations_ = 0;
  int inner_slow_steps_ = 0;
  bool rows_current_ = false;
  // rows_ belong to this target kind, if not to inner_bend_.
  bool rows_valid_ = false;
  // A streamed target arrived: its step comes first in the next run().
  bool track_pending_ = false;
  // Streamed steps moved inner_bend_ while an evaluation ran.
  bool tracked_since_outer_ = false;
  // Streamed steps taken on rows of an earlier point, and how many are let go
  // before the rows are renewed.
  int stale_row_steps_ = 0;
  static constexpr int kMaxStaleRowSteps = 4;
  bool active_[Max] = {};
  IkPreference<S, Max> preference_{};
  // The next step has the preference's part (not after one it spoilt).
  bool prefer_in_step_ = true;
  Eigen::Matrix<S, 6, kMaxColumns, Eigen::RowMajor> rows_ = Eigen::Matrix<S, 6, kMaxColumns, Eigen::RowMajor>::Zero();
};

}  // namespace cdcr::model
