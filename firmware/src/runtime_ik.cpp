// The runtime's IK requests: a target's start, each cycle's slice of solver
// work, and the request's end with its setpoints and report.
#include "cdcr/firmware/runtime.hpp"

namespace cdcr::firmware {

void Runtime::start_solve(const Pose& target, const protocol::TargetPositionZ& commit) {
  // A streamed target continues the running streamed request's work.
  const bool retarget = solving_ && solving_tracking_ && commit.tracking;
  if (solving_) end_solve(protocol::IkOutcome::superseded);
  Joints initial(2 * geometry_.segment_count);
  if (has_setpoints_) {
    initial = setpoint_joints_;
  } else if (has_pose_) {
    initial = latest_pose_.joints;
  } else {
    straight_start(initial);
  }
  const model::IkTargetKind kind =
      commit.mode == protocol::TargetMode::pose ? model::IkTargetKind::pose : model::IkTargetKind::position;
  model::Status started = model::Status::ok;
  // A streamed target starts where the last request's best point is, with
  // the correction there and its slope known; any other from the setpoints.
  started = retarget          ? solver_.retarget(target, kind, initial)
            : commit.tracking ? solver_.start_warm(target, kind, initial)
                              : solver_.start(target, kind, initial);
  solving_sequence_ = commit.sequence;
  solving_mode_ = commit.mode;
  solving_tracking_ = commit.tracking;
  solving_refuses_extrapolation_ = commit.refuse_extrapolating;
  checking_solution_ = false;
  solution_retried_ = false;
  solving_target_ = target;
  solving_cycles_ = 0;
  // A streamed target that takes over the work may still send the point
  // already sent only once.
  if (!retarget) published_best_bend_.resize(0);
  if (started != model::Status::ok) {
    last_ik_report_ = IkReport{};
    last_ik_report_.sequence = commit.sequence;
    last_ik_report_.model_status = started;
    last_ik_report_.outcome = protocol::IkOutcome::unreachable;
    record_event(FaultCode::target_unreachable, FaultDetail(started));
    publish_ik_report();
    return;
  }
  solving_end_ = model::IkSolveState::running;
  solving_ = true;
}

// A slight bend keeps the first Jacobian away from the straight pose.
void Runtime::straight_start(Joints& joints) const {
  joints.resize(2 * geometry_.segment_count);
  for (int s = 0; s < geometry_.segment_count; ++s) {
    joints[2 * s] = Scalar(0);
    joints[2 * s + 1] = Scalar(0.1);
  }
}

// A cycle's IK slice: solver steps within ik_units_per_cycle_, and the
// request's end (setpoints and report, kWorkCosts.ik_finish) when what is
// left of the slice pays for it; otherwise the end goes out first thing in
// the next cycle's slice.
void Runtime::continue_solve() {
  if (state_ != RuntimeState::run && state_ != RuntimeState::degraded) return;
  ++solving_cycles_;
  if (checking_solution_) {
    continue_solution_check();
    return;
  }
  if (solving_end_ != model::IkSolveState::running) {
    ik_units_last_cycle_ = kWorkCosts.ik_finish;
    finish_solve(solving_end_);
    return;
  }
  model::IkSolveState end = model::IkSolveState::running;
  std::uint32_t spent = 0;
  [&](Solver& solver) {
    // A streamed request keeps room for its setpoints in every cycle; on a
    // core where a step and the setpoints do not fit in one slice, a cycle
    // first sends what the last one's step found, then steps again.
    // (kMinIkUnitsPerCycle covers the setpoints alone.)
    const bool room_for_both = ik_units_per_cycle_ >= kWorkCosts.ik_finish + kIkWorkCosts.nominal_step;
    if (solving_tracking_ && !room_for_both && publish_tracking_point(solver)) spent = kWorkCosts.ik_finish;
    const std::uint32_t reserved = solving_tracking_ && room_for_both ? kWorkCosts.ik_finish : 0;
    spent += solver.run(ik_units_per_cycle_ - spent - reserved);
    end = solver.state();
    if (end != model::IkSolveState::running || !solving_tracking_) return;
    if (spent + kWorkCosts.ik_finish > ik_units_per_cycle_) return;
    if (publish_tracking_point(solver)) spent += kWorkCosts.ik_finish;
  }(solver_);
  ik_units_last_cycle_ = spent;
  // A request that has used its cycles ends as not converged.
  if (end == model::IkSolveState::running && solving_cycles_ >= kMaxIkCycles) end = model::IkSolveState::not_converged;
  if (end != model::IkSolveState::running) {
    if (spent + kWorkCosts.ik_finish <= ik_units_per_cycle_) {
      ik_units_last_cycle_ += kWorkCosts.ik_finish;
      finish_solve(end);
    } else {
      solving_end_ = end;
    }
  } else if (solving_cycles_ % kIkProgressEveryCycles == 0) {
    fill_ik_report(protocol::IkOutcome::in_progress);
    publish_ik_report();
  }
}

// Streamed targets: the best point so far, when it is close and new;
// between evaluations the linearised solve's point, when it is closer.
// Returns whether setpoints went out.
bool Runtime::publish_tracking_point(Solver& solver) {
  // A point not yet checked for extrapolation is not sent when the target
  // refuses extrapolating solutions.
  if (!solver.has_best() || solving_refuses_extrapolation_) return false;
  const bool linearised =
      solver.has_linearised_point() && solver.linearised_position_error_mm() < solver.best_position_error_mm();
  const Joints& bend = linearised ? solver.linearised_bend() : solver.best_bend();
  const Scalar position_error = linearised ? solver.linearised_position_error_mm() : solver.best_position_error_mm();
  const Scalar orientation_error =
      linearised ? solver.linearised_orientation_error_rad() : solver.best_orientation_error_rad();
  const bool close = position_error <= kTrackingPublishPositionErrorMm &&
                     (solving_mode_ == protocol::TargetMode::position ||
                      orientation_error <= kTrackingPublishOrientationErrorRad);
  const bool is_new = published_best_bend_.size() != bend.size() || published_best_bend_ != bend;
  if (!close || !is_new) return false;
  if (!set_setpoints(linearised ? solver.linearised_joints() : solver.best_joints())) return false;
  published_best_bend_ = bend;
  publish_setpoints();
  return true;
}

void Runtime::fill_ik_report(protocol::IkOutcome outcome) {
  last_ik_report_ = IkReport{};
  last_ik_report_.sequence = solving_sequence_;
  last_ik_report_.outcome = outcome;
  last_ik_report_.cycles = solving_cycles_;
  [&](Solver& solver) {
    last_ik_report_.model_status = solver.state() == model::IkSolveState::failed ? solver.status()
                                   : solver.state() == model::IkSolveState::converged
                                       ? model::Status::ok
                                       : model::Status::ik_not_converged;
    last_ik_report_.iterations = solver.iterations();
    last_ik_report_.position_error_mm = solver.best_position_error_mm();
    last_ik_report_.orientation_error_rad =
        solving_mode_ == protocol::TargetMode::pose ? solver.best_orientation_error_rad() : Scalar(0);
  }(solver_);
}

void Runtime::finish_solve(model::IkSolveState end) {
  bool reached = false;
  Joints joints;
  [&](Solver& solver) {
    if (end == model::IkSolveState::failed || !solver.has_best()) return;
    // A residual within the accepted one counts, even if the solver's own
    // (float rounding-level) tolerance was not met.
    reached = end == model::IkSolveState::converged ||
              (solver.best_position_error_mm() <= kIkAcceptedPositionErrorMm &&
               (solving_mode_ == protocol::TargetMode::position ||
                solver.best_orientation_error_rad() <= kIkAcceptedOrientationErrorRad));
    joints = solver.best_joints();
  }(solver_);
  solving_end_ = end;
  if (reached && solving_refuses_extrapolation_ && begin_solution_check(joints)) return;
  conclude_solve(reached, joints);
}

// The request's end: setpoints and a converged report, or setpoints held.
void Runtime::conclude_solve(bool reached, const Joints& joints) {
  fill_ik_report(protocol::IkOutcome::converged);
  if (solving_end_ != model::IkSolveState::converged && solving_end_ != model::IkSolveState::failed) {
    last_ik_report_.model_status = model::Status::ik_not_converged;
  }
  if (reached && set_setpoints(joints)) {
    publish_setpoints();
  } else {
    // Setpoints held: the drives keep the last commanded lengths.
    last_ik_report_.outcome = protocol::IkOutcome::unreachable;
    record_event(FaultCode::target_unreachable, FaultDetail(last_ik_report_.model_status));
  }
  solving_ = false;
  checking_solution_ = false;
  publish_ik_report();
}

// A solution for a target that refuses extrapolation: outside the fitted
// input range it is refused at once; with a variance block its variance is
// computed over the next cycles' IK slices (continue_solution_check).
// Returns false when there is nothing to check (DEGRADED: no model to
// extrapolate; RUN without a variance block and within range) and the
// request ends as any other.
bool Runtime::begin_solution_check(const Joints& joints) {
  if (mode_ != RuntimeState::run || !uncertainty_.bound()) return false;
  Scalar coordinates[Correction::kMaxInputs];
  correction_.kernel_coordinates(model::bend_from_joints(joints), coordinates);
  if (uncertainty_.outside_range(coordinates)) {
    retry_or_refuse();
    return true;
  }
  if (!uncertainty_.has_variance()) return false;
  model::Vec3<Scalar> tip = model::Vec3<Scalar>::Zero();  // only the flag is used, not the radii
  uncertainty_.begin_evaluation(coordinates, tip, solution_check_);
  checked_joints_ = joints;
  checking_solution_ = true;
  return true;
}

// The robot is redundant: another start may find a solution inside the
// data where the first did not. One more search from the straight start,
// in the same request (its cycles and report), then the refusal.
void Runtime::retry_or_refuse() {
  checking_solution_ = false;
  Joints start;
  straight_start(start);
  const model::IkTargetKind kind =
      solving_mode_ == protocol::TargetMode::pose ? model::IkTargetKind::pose : model::IkTargetKind::position;
  if (!solution_retried_ && solver_.start(solving_target_, kind, start) == model::Status::ok) {
    solution_retried_ = true;
    solving_end_ = model::IkSolveState::running;
    return;
  }
  end_solve(protocol::IkOutcome::refused_extrapolating);
}

void Runtime::continue_solution_check() {
  std::uint32_t spent = 0;
  if (!uncertainty_.evaluation_finished(solution_check_)) {
    spent = uncertainty_.continue_evaluation(solution_check_, ik_units_per_cycle_);
  }
  ik_units_last_cycle_ = spent;
  if (!uncertainty_.evaluation_finished(solution_check_) || spent + kWorkCosts.ik_finish > ik_units_per_cycle_) return;
  ik_units_last_cycle_ += kWorkCosts.ik_finish;
  if (uncertainty_.evaluation_result(solution_check_).extrapolating) {
    retry_or_refuse();
  } else {
    conclude_solve(true, checked_joints_);
  }
}

void Runtime::end_solve(protocol::IkOutcome outcome) {
  fill_ik_report(outcome);
  solving_ = false;
  checking_solution_ = false;
  publish_ik_report();
}

// The frames are encoded here, where each length is checked, and kept for
// publish_setpoints().
bool Runtime::set_setpoints(const Joints& joints) {
  Cables cables;
  if (model::cables_from_joints(joints, geometry_, cables) != model::Status::ok) return false;
  hal::CanFrame frames[kMaxSegments];
  for (int s = 0; s < geometry_.segment_count; ++s) {
    const protocol::CableSetpoint setpoint{s, {cables[4 * s], cables[4 * s + 1], cables[4 * s + 2], cables[4 * s + 3]}};
    if (!protocol::encode(setpoint, frames[s])) return false;
  }
  for (int s = 0; s < geometry_.segment_count; ++s) setpoint_frames_[s] = frames[s];
  setpoints_mm_ = cables;
  setpoint_joints_ = joints;
  has_setpoints_ = true;
  return true;
}

void Runtime::publish_setpoints() {
  for (int s = 0; s < geometry_.segment_count; ++s) send(setpoint_frames_[s]);
  setpoints_published_ += 1;
}

void Runtime::publish_ik_report() {
  const IkReport& r = last_ik_report_;
  hal::CanFrame frame;
  protocol::encode(protocol::IkReport{r.sequence, r.outcome, r.iterations, r.cycles, double(r.position_error_mm),
                                      double(r.orientation_error_rad)},
                   frame);
  send(frame);
}

}  // namespace cdcr::firmware
