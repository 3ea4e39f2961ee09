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
//     at its own point; the linearisation's point changes only when it
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


#include <cstdint>
#include <limits>
#include <type_traits>

#include "cdcr/model/chain.hpp"
#include "cdcr/model/geometry.hpp"
#include "cdcr/model/ik/best_point.hpp"
#include "cdcr/model/ik/correction_evaluation.hpp"
#include "cdcr/model/ik/linearisation.hpp"
#include "cdcr/model/ik/lm_solve.hpp"
#include "cdcr/model/ik/options.hpp"
#include "cdcr/model/ik/problem.hpp"
#include "cdcr/model/ik/restarts.hpp"
#include "cdcr/model/ik/solve_flow.hpp"
#include "cdcr/model/ik/stream.hpp"
#include "cdcr/model/se3.hpp"
#include "cdcr/model/status.hpp"
#include "cdcr/model/types.hpp"
#include "cdcr/model/work_costs.hpp"

namespace cdcr::model {

// The solve's parts (ik/): the target and options it measures against
// (Problem), the correction between evaluations (Linearisation), the LM
// solve on it (LmSolve), the preference's part of a step (Preference), a
// streamed target's step (Stream), the stall rule and the restart list
// (Restarts), and where the solve stands (SolveFlow: every state and every
// transition). IkSolver sequences them within the budget.
template <typename S, int Max, typename Correction = NoCorrection>
class IkSolver {
  static constexpr bool kSliced = is_sliced_correction<Correction>::value;
  using Event = ik::Event;
  using Phase = ik::Phase;

 public:
  using Joints = JointVector<S, Max>;
  using Residual = Eigen::Matrix<S, 6, 1>;
  static constexpr int kMaxColumns = 2 * Max;
  // Secant steps shorter than this (rad of bend) are not learned from.
  static constexpr S kMinSecantStep = ik::Linearisation<S, Max>::kMinSecantStep;
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
    problem_.configure(geometry, options);
    evaluation_.bind(correction);
    costs_ = costs;
    state_ = IkSolveState::idle;
    flow_.on(Event::configured);
    preference_.clear();
  }

  // Where to prefer solutions (IkPreference); off until set, and again after
  // configure(). Takes effect from the next step.
  void set_preference(const IkPreference<S, Max>& preference) { preference_.set(preference, problem_.geometry); }

  // Starts a solve, abandoning any running one, from initial_joints ((alpha,
  // theta) pairs within the limits) with no knowledge of the correction.
  Status start(const Pose<S>& target, IkTargetKind kind, const Joints& initial_joints) {
    if (const Status s = reset(target, kind); s != Status::ok) return s;
    flow_.on(Event::cold_start);
    if (const Status s = check_joints(initial_joints, *problem_.geometry); s != Status::ok) return fail(s);
    flow_.on(Event::slope_lost);
    const Joints bend = bend_from_joints(initial_joints);
    best_.bend = bend;
    state_ = IkSolveState::running;
    begin_outer(bend);
    return status_;
  }

  // Starts a solve from the best point of the previous one (a target near
  // the last, as along a streamed path): the correction there is known, and
  // the slope learned so far is kept. Without a previous point, as start().
  Status start_warm(const Pose<S>& target, IkTargetKind kind, const Joints& fallback_joints) {
    if (!flow_.has_warm_start() || best_.warm_bend.size() != 2 * problem_.geometry->segment_count) {
      return start(target, kind, fallback_joints);
    }
    if (const Status s = reset(target, kind); s != Status::ok) return s;
    best_.bend = best_.warm_bend;
    lin_.point = best_.warm_bend;
    lin_.eps = best_.warm_eps;
    state_ = IkSolveState::running;
    flow_.on(Event::warm_start);
    return status_;
  }

  // Starts a solve from initial_joints; when they are the best point of the
  // previous solve (a target started from the setpoints the last one left),
  // as start_warm(): the correction there is known, which saves the first
  // evaluation, and the next evaluation brings the gradient (the last
  // target's slope alone costs latency: tools/bench/README.md, IK section).
  Status start_near(const Pose<S>& target, IkTargetKind kind, const Joints& initial_joints) {
    if (flow_.has_warm_start() && problem_.geometry != nullptr && initial_joints.size() == best_.warm_bend.size() &&
        initial_joints.allFinite() &&
        (bend_from_joints(initial_joints) - best_.warm_bend).cwiseAbs().maxCoeff() <= kSameBendRad) {
      const Status s = start_warm(target, kind, initial_joints);
      flow_.on(Event::near_start);
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
    const IkTargetKind previous_kind = problem_.kind;
    problem_.target = target;
    problem_.kind = kind;
    corrections_ = 0;
    iterations_ = 0;
    restarts_.reset();
    units_spent_ = 0;
    // The secant pair stays (the correction does not depend on the target);
    // the last residual, measured against the old target, does not count.
    lin_.previous_cost = std::numeric_limits<S>::infinity();
    if (flow_.has_warm_start()) {
      best_.rescore_warm_start(problem_);
    } else {
      best_.forget();
    }
    if (kind != previous_kind) flow_.on(Event::kind_changed);
    if (flow_.linearised()) {
      // The linearised model and its Jacobian do not depend on the target
      // either: the solve on it goes on towards the new one, with a step
      // first thing in the next run().
      lm_.rescore(problem_);
      flow_.on(Event::streamed_target);
      // Its iteration bounds and damping carry on: a target that moves every
      // cycle must not keep the solve from ever reaching the next evaluation,
      // nor hold the damping where it hides the weakly actuated directions.
      if (flow_.phase() == Phase::inner && lm_.done()) finish_inner();
    }
    return status_;
  }

  // Does whole steps while their cost fits in `budget` units; returns the
  // units spent (0 when nothing fits or nothing is left to do). A correction
  // evaluation is sliced to fit; a nominal iteration runs only when its whole
  // cost fits.
  std::uint32_t run(std::uint32_t budget) {
    std::uint32_t spent = 0;
    if (flow_.stream_step_due() && state_ == IkSolveState::running) {
      // A streamed target's step comes first, on the linearisation and the
      // rows at hand (a Jacobian from a step or two back does for a target
      // a fraction of a millimetre on): the setpoints follow the stream
      // every cycle while evaluations and Jacobians go on in the rest.
      flow_.on(Event::stream_step_taken_up);
      if (flow_.linearised() && flow_.rows_valid()) spent = track_step(budget);
    }
    while (state_ == IkSolveState::running) {
      const std::uint32_t left = budget - spent;
      const Phase phase = flow_.phase();
      if (phase == Phase::evaluate && flow_.linearised() && stream_.rows_overdue() &&
          left >= costs_.nominal_jacobian) {
        // Streamed steps have gone on on old rows for a while: new ones at
        // the current point, before the evaluation's next slice.
        spent += costs_.nominal_jacobian;
        update_rows();
        continue;
      }
      if (phase == Phase::evaluate) {
        if (left == 0) break;
        Status status = Status::ok;
        const std::uint32_t used = evaluation_.advance(left, status);
        if (status != Status::ok) fail(status);
        spent += used;
        if (state_ != IkSolveState::running) break;
        if (!evaluation_.finished()) {
          if (used == 0) break;  // the next slice does not fit
          continue;
        }
        lin_.point = evaluation_.point();
        const bool with_gradient = evaluation_.has_gradient();
        evaluation_.result(lin_.eps, lin_.gradient);
        ++corrections_;
        flow_.on(with_gradient ? Event::evaluated_with_gradient : Event::evaluated_mean);
        continue;
      }
      if (phase == Phase::outer_step) {
        if (left < costs_.outer_step) break;
        spent += costs_.outer_step;
        outer_step();
        continue;
      }
      // Phase::inner
      if (!flow_.rows_current()) {
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
  IkTargetKind kind() const { return problem_.kind; }
  const Pose<S>& target() const { return problem_.target; }
  // Correction evaluations and nominal LM iterations spent on this target.
  int corrections() const { return corrections_; }
  int iterations() const { return iterations_; }
  int restarts() const { return restarts_.count(); }
  // Units run() has spent on this target.
  std::uint64_t units_spent() const { return units_spent_; }
  bool has_best() const { return best_.exists(); }
  // The best point whose compensated residual has been evaluated exactly,
  // as (alpha, theta) pairs, and its residual.
  Joints best_joints() const { return problem_.clamped_joints(best_.bend); }
  S best_position_error_mm() const { return best_.position_error; }
  // The linearised solve's current point, while one runs: its correction is
  // predicted from the last evaluation and the slope, not evaluated, so it is
  // for following a stream of targets between evaluations.
  bool has_linearised_point() const { return state_ == IkSolveState::running && flow_.linearised(); }
  const Joints& linearised_bend() const { return lm_.bend(); }
  Joints linearised_joints() const { return problem_.clamped_joints(lm_.bend()); }
  S linearised_position_error_mm() const { return lm_.position_error(); }
  S linearised_orientation_error_rad() const { return lm_.orientation_error(); }
  const Joints& best_bend() const { return best_.bend; }
  S best_orientation_error_rad() const { return best_.orientation_error; }

 private:
  Status reset(const Pose<S>& target, IkTargetKind kind) {
    state_ = IkSolveState::failed;
    status_ = Status::ok;
    corrections_ = 0;
    iterations_ = 0;
    restarts_.reset();
    units_spent_ = 0;
    flow_.on(Event::target_set);
    best_.forget();
    if (problem_.geometry == nullptr) return status_ = Status::invalid_geometry;
    if (!target.all_finite()) return fail(Status::non_finite_input);
    problem_.target = target;
    problem_.kind = kind;
    return Status::ok;
  }

  bool wants_gradient() const {
    if (!(problem_.options.gradient_refresh_ratio > S(0))) return false;
    if constexpr (!ik::CorrectionEvaluation<S, Max, Correction>::kOffersGradient) return false;
    return !flow_.slope_known() || flow_.gradient_with_next_evaluation();
  }

  void begin_outer(const Joints& bend) {
    flow_.on(Event::outer_begun);
    if (!evaluation_.bound()) {
      // The nominal model: the correction and its slope are zero.
      lin_.point = bend;
      lin_.eps.setZero();
      lin_.gradient.setZero(6, lin_.point.size());
      ++corrections_;
      flow_.on(Event::evaluated_with_gradient);
      return;
    }
    // The linearisation in use (lin_.point) stays until this evaluation
    // ends: a streamed target's steps go on on it meanwhile.
    if (const Status s = evaluation_.begin(bend, wants_gradient()); s != Status::ok) {
      fail(s);
      return;
    }
    flow_.on(Event::evaluation_begun);
  }

  // The correction at lin_.point is known: test convergence on the
  // compensated model, learn the slope, and set up the next linearised solve.
  void outer_step() {
    const IkSolverOptions<S>& options = problem_.options;
    if (!lin_.eps.allFinite()) {
      fail(Status::correction_failed);
      return;
    }

    const Pose<S> tip = exp(lin_.eps) * forward_kinematics_bend(lin_.point, *problem_.geometry);
    Residual residual;
    S position_error = S(0);
    S orientation_error = S(0);
    problem_.residual_of(tip, residual, position_error, orientation_error);
    const S cost = residual.squaredNorm();

    lin_.learn_slope(options, flow_);
    if (cost < best_.cost) {
      best_.keep(lin_.point, lin_.eps, tip, cost, position_error, orientation_error);
      flow_.on(Event::best_kept);
    }
    if (problem_.within_tolerance(position_error, orientation_error)) {
      state_ = IkSolveState::converged;
      return;
    }
    restarts_.record(flow_.has_previous(), cost, lin_.previous_cost);
    if (corrections_ >= options.max_corrections || iterations_ >= options.max_iterations) {
      state_ = IkSolveState::not_converged;
      return;
    }
    // A stall near the tolerance is the arithmetic's floor and ends the
    // solve; farther out the start is bad and the next one is tried.
    if (restarts_.stalled(position_error, options)) {
      if (ik::Restarts<S, Max>::at_floor(position_error, options) || !restart()) {
        state_ = IkSolveState::not_converged;
      }
      return;
    }
    // The next evaluation brings the gradient when the slope has gone stale
    // (poor contraction away from the arithmetic's floor), when start_near()
    // asked for it, and in a stream, whose steps lean on the slope the most
    // (tools/bench/README.md, IK section).
    const bool gradient_next = flow_.streamed_point() || flow_.gradient_after_first_outer_step() ||
                               (flow_.has_previous() && cost > options.gradient_refresh_ratio * lin_.previous_cost &&
                                position_error > S(20) * options.position_tolerance_mm);
    const bool had_damping = flow_.has_damping();
    lin_.remember(cost);
    flow_.on(gradient_next ? Event::outer_done_gradient_next : Event::outer_done);
    // The linearised solve starts where the exact model was just evaluated,
    // or where a streamed target's steps have taken it since.
    lm_.template begin<kSliced>(problem_, lin_, flow_, position_error, orientation_error, had_damping);
    if (lm_.done()) finish_inner();
  }

  // A new start after a stall (ik::Restarts), unless the bound is reached.
  bool restart() {
    Joints bend;
    if (!restarts_.next_start(problem_.options, *problem_.geometry, bend)) return false;
    flow_.on(Event::restarted);
    begin_outer(bend);
    return true;
  }

  Status fail(Status status) {
    status_ = status;
    state_ = IkSolveState::failed;
    return status;
  }

  // A streamed target's step on the linearisation in hand; returns the
  // units spent. The stream's steps are the pose task's alone: a target
  // that moves every cycle is followed most closely by the smallest motion
  // (tools/bench/README.md, IK section); the preference acts in the
  // iterations between.
  std::uint32_t track_step(std::uint32_t budget) {
    return stream_.step(
        budget, costs_, flow_, [this] { update_rows(); },
        [this] {
          if (flow_.phase() == Phase::inner) {
            inner_iteration(false);
          } else {
            ++iterations_;
            lm_.template try_step<6>(problem_, lin_, preference_, flow_, false);
            flow_.on(Event::stream_moved_point);
          }
        });
  }

  void finish_inner() { begin_outer(lm_.bend()); }

  // Position targets use the same six rows with the orientation rows and
  // residual zero (ik::LmSolve::update_rows).
  void update_rows() {
    lm_.template update_rows<6>(problem_, lin_, flow_);
    stream_.rows_renewed();
  }

  // One LM iteration of the linearised solve: the damped step, then whether
  // the solve restarts, goes on, or hands over to the next evaluation.
  void inner_iteration(bool may_prefer = true) {
    ++iterations_;
    lm_.count_iteration();
    lm_.template try_step<6>(problem_, lin_, preference_, flow_, may_prefer);

    if (lm_.stuck(lin_.point, problem_.options)) {
      if (!restart()) state_ = IkSolveState::not_converged;
      return;
    }
    if (lm_.template hand_over<kSliced>(problem_.options) || iterations_ >= problem_.options.max_iterations) {
      finish_inner();
    }
  }

  IkWorkCosts costs_{};
  ik::Problem<S, Max> problem_{};

  IkSolveState state_ = IkSolveState::idle;
  Status status_ = Status::ok;
  ik::SolveFlow flow_{};
  int corrections_ = 0;
  int iterations_ = 0;
  std::uint64_t units_spent_ = 0;

  // The outer iteration: the evaluation in progress, the correction
  // between evaluations, the restarts and the best point.
  ik::CorrectionEvaluation<S, Max, Correction> evaluation_{};
  ik::Linearisation<S, Max> lin_{};
  ik::Restarts<S, Max> restarts_{};
  ik::BestPoint<S, Max> best_{};

  // The linearised solve between two evaluations and a streamed target's
  // steps on it.
  ik::LmSolve<S, Max> lm_{};
  ik::Stream stream_{};
  ik::Preference<S, Max> preference_{};
};

}  // namespace cdcr::model
