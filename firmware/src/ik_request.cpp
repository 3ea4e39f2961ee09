#include "cdcr/firmware/ik_request.hpp"

#include "cdcr/firmware/ik_settings.hpp"

namespace cdcr::firmware {

void IkRequest::start(const Pose& target, const TargetRequest& request, const PoseEstimate* latest_pose) {
  // Until it ends, the report names the new target; one in progress is
  // reported superseded.
  report_ = IkReport{};
  report_.sequence = request.sequence;
  // A streamed target continues the running streamed request's work.
  const bool retarget = solving_ && tracking_ && request.tracking;
  if (solving_) end(protocol::IkOutcome::superseded);
  Joints initial(2 * model_.geometry.segment_count);
  if (has_setpoints_) {
    initial = setpoint_joints_;
  } else if (latest_pose != nullptr) {
    initial = latest_pose->joints;
  } else {
    straight_start(initial);
  }
  const model::IkTargetKind kind =
      request.mode == protocol::TargetMode::pose ? model::IkTargetKind::pose : model::IkTargetKind::position;
  model::Status started = model::Status::ok;
  // Only a target that refuses extrapolation gets the preference: the
  // refusing ones need it (inside the data: 1 of 20 refused without it, 0
  // with it, on both boards); for every target, in the QEMU workload, the
  // paper's pose targets took p50/p99 M7 23/42 and M4F 17/37 cycles (21/54
  // and 15/37 without), at a third of the gain M7 21/41 and M4F 17/45.
  solver_.set_preference(request.refuse_extrapolating ? preference_ : model::IkPreference<Scalar, kMaxSegments>{});
  // A streamed target starts where the last request's best point is, with
  // the correction there and its slope known; any other from the setpoints,
  // and with the same knowledge when they are that point.
  started = retarget          ? solver_.retarget(target, kind, initial)
            : request.tracking ? solver_.start_warm(target, kind, initial)
                              : solver_.start_near(target, kind, initial);
  sequence_ = request.sequence;
  mode_ = request.mode;
  tracking_ = request.tracking;
  refuses_extrapolation_ = request.refuse_extrapolating;
  checking_solution_ = false;
  solution_retries_ = 0;
  target_ = target;
  cycles_ = 0;
  if (started != model::Status::ok) {
    report_ = IkReport{};
    report_.sequence = request.sequence;
    report_.model_status = started;
    report_.outcome = protocol::IkOutcome::unreachable;
    outbox_.record_event(FaultCode::target_unreachable, FaultDetail(started));
    publish_report();
    return;
  }
  end_ = model::IkSolveState::running;
  solving_ = true;
}

void IkRequest::configure() {
  // In DEGRADED the same solver solves the nominal model.
  solver_.configure(model_.geometry, model_.compensated ? &solver_correction_ : nullptr,
                    runtime_solver_options<Scalar>(), kIkWorkCosts);
  preference_ = ik_preference(model_.geometry, model_.compensated ? &model_.image : nullptr);
}

void IkRequest::refuse(std::uint8_t sequence, protocol::IkOutcome outcome) {
  report_ = IkReport{};
  report_.sequence = sequence;
  report_.outcome = outcome;
  publish_report();
}

// A slight bend keeps the first Jacobian away from the straight pose.
void IkRequest::straight_start(Joints& joints) const {
  joints = ik_straight_start(model_.geometry);
}

// A cycle's IK slice: solver steps within `units`, and the request's end
// (setpoints and report, kWorkCosts.ik_finish) when what is left of the
// slice pays for it; otherwise the end goes out first thing in the next
// cycle's slice.
std::uint32_t IkRequest::continue_slice(std::uint32_t units) {
  ++cycles_;
  if (checking_solution_) return continue_solution_check(units);
  if (end_ != model::IkSolveState::running) {
    finish(end_);
    return kWorkCosts.ik_finish;
  }
  model::IkSolveState end = model::IkSolveState::running;
  std::uint32_t spent = 0;
  [&](Solver& solver) {
    // A streamed request keeps room for its setpoints in every cycle; on a
    // core where a step and the setpoints do not fit in one slice, a cycle
    // first sends what the last one's step found, then steps again.
    // (kMinIkUnitsPerCycle covers the setpoints alone.)
    const bool room_for_both = units >= kWorkCosts.ik_finish + kIkWorkCosts.nominal_step;
    if (tracking_ && !room_for_both && publish_tracking_point(solver)) spent = kWorkCosts.ik_finish;
    const std::uint32_t reserved = tracking_ && room_for_both ? kWorkCosts.ik_finish : 0;
    spent += solver.run(units - spent - reserved);
    end = solver.state();
    if (end != model::IkSolveState::running || !tracking_) return;
    if (spent + kWorkCosts.ik_finish > units) return;
    if (publish_tracking_point(solver)) spent += kWorkCosts.ik_finish;
  }(solver_);
  // A request that has used its cycles ends as not converged.
  if (end == model::IkSolveState::running && cycles_ >= kMaxIkCycles) end = model::IkSolveState::not_converged;
  if (end != model::IkSolveState::running) {
    if (spent + kWorkCosts.ik_finish <= units) {
      spent += kWorkCosts.ik_finish;
      finish(end);
    } else {
      end_ = end;
    }
  } else if (cycles_ % kIkProgressEveryCycles == 0) {
    fill_report(protocol::IkOutcome::in_progress);
    publish_report();
  }
  return spent;
}

// Streamed targets: setpoints in every cycle of the request, the best point
// so far or, between evaluations, the linearised solve's point when its
// predicted residual is smaller. The best point is never farther from the
// newest target than the setpoints in place (a streamed request starts from
// the last one's best point), so sending it is never a step back; holding
// the old setpoints instead left the drives a cycle or more behind a moving
// target. Returns whether setpoints went out.
bool IkRequest::publish_tracking_point(Solver& solver) {
  // A point not yet checked for extrapolation is not sent when the target
  // refuses extrapolating solutions.
  if (!solver.has_best() || refuses_extrapolation_) return false;
  const bool linearised =
      solver.has_linearised_point() && solver.linearised_position_error_mm() < solver.best_position_error_mm();
  if (!set_setpoints(linearised ? solver.linearised_joints() : solver.best_joints())) return false;
  publish_setpoints();
  return true;
}

void IkRequest::fill_report(protocol::IkOutcome outcome) {
  report_ = IkReport{};
  report_.sequence = sequence_;
  report_.outcome = outcome;
  report_.cycles = cycles_;
  [&](Solver& solver) {
    report_.model_status = solver.state() == model::IkSolveState::failed ? solver.status()
                                   : solver.state() == model::IkSolveState::converged
                                       ? model::Status::ok
                                       : model::Status::ik_not_converged;
    report_.iterations = solver.iterations();
    report_.position_error_mm = solver.best_position_error_mm();
    report_.orientation_error_rad =
        mode_ == protocol::TargetMode::pose ? solver.best_orientation_error_rad() : Scalar(0);
  }(solver_);
}

void IkRequest::finish(model::IkSolveState end) {
  bool reached = false;
  Joints joints;
  [&](Solver& solver) {
    if (end == model::IkSolveState::failed || !solver.has_best()) return;
    // A residual within the accepted one counts, even if the solver's own
    // (float rounding-level) tolerance was not met.
    reached = end == model::IkSolveState::converged ||
              (solver.best_position_error_mm() <= kIkAcceptedPositionErrorMm &&
               (mode_ == protocol::TargetMode::position ||
                solver.best_orientation_error_rad() <= kIkAcceptedOrientationErrorRad));
    joints = solver.best_joints();
  }(solver_);
  end_ = end;
  if (reached && refuses_extrapolation_ && begin_solution_check(joints)) return;
  conclude(reached, joints);
}

// The request's end: setpoints and a converged report, or setpoints held.
void IkRequest::conclude(bool reached, const Joints& joints) {
  fill_report(protocol::IkOutcome::converged);
  if (end_ != model::IkSolveState::converged && end_ != model::IkSolveState::failed) {
    report_.model_status = model::Status::ik_not_converged;
  }
  if (reached && set_setpoints(joints)) {
    publish_setpoints();
  } else {
    // Setpoints held: the drives keep the last commanded lengths.
    report_.outcome = protocol::IkOutcome::unreachable;
    outbox_.record_event(FaultCode::target_unreachable, FaultDetail(report_.model_status));
  }
  solving_ = false;
  checking_solution_ = false;
  publish_report();
}

// A solution for a target that refuses extrapolation: outside the fitted
// input range it is refused at once where the range flags (images before
// 2.6, or without a variance block); with a variance block its variance is
// computed over the next cycles' IK slices (continue_solution_check).
// Returns false when there is nothing to check (DEGRADED: no model to
// extrapolate; RUN without a variance block and within range) and the
// request ends as any other.
bool IkRequest::begin_solution_check(const Joints& joints) {
  if (!model_.compensated || !model_.uncertainty.bound()) return false;
  Scalar coordinates[Correction::kMaxInputs];
  model_.correction.kernel_coordinates(model::bend_from_joints(commanded_joints(model_, joints)), coordinates);
  if (model_.uncertainty.range_flags() && model_.uncertainty.outside_range(coordinates)) {
    retry_or_refuse(joints);
    return true;
  }
  if (!model_.uncertainty.has_variance()) return false;
  model::Vec3<Scalar> tip = model::Vec3<Scalar>::Zero();  // only the flag is used, not the radii
  model_.uncertainty.begin_evaluation(coordinates, tip, solution_check_);
  checked_joints_ = joints;
  checking_solution_ = true;
  return true;
}

// The robot is redundant: another start may find a solution inside the
// data where the first did not. First from the refused solution with every
// bend halved, then quartered (a redundant solution outside the data
// usually bends some segments further than the data did, and the shrunk
// start lies in the basin of a solution with smaller bends), then from the
// straight start; in the same request (its cycles and report), then the
// refusal. In the QEMU workload this took the targets made inside the data
// that were refused from 4 of 20 (M7) and 9 of 20 (M4F), with the straight
// start alone, to 1 of 20 on both; a fourth and fifth start (three
// quarters, a tenth of the bends) changed nothing.
void IkRequest::retry_or_refuse(const Joints& refused) {
  // The refused solution's bends scaled by these, then the straight start.
  static constexpr Scalar kRetryBendScales[] = {Scalar(0.5), Scalar(0.25)};
  constexpr int kRetries = int(sizeof(kRetryBendScales) / sizeof(kRetryBendScales[0])) + 1;
  checking_solution_ = false;
  Joints start;
  if (solution_retries_ < kRetries - 1) {
    start = refused;
    for (int s = 0; s < model_.geometry.segment_count; ++s) start[2 * s + 1] *= kRetryBendScales[solution_retries_];
  } else {
    straight_start(start);
  }
  const model::IkTargetKind kind =
      mode_ == protocol::TargetMode::pose ? model::IkTargetKind::pose : model::IkTargetKind::position;
  if (solution_retries_ < kRetries && solver_.start(target_, kind, start) == model::Status::ok) {
    ++solution_retries_;
    end_ = model::IkSolveState::running;
    return;
  }
  end(protocol::IkOutcome::refused_extrapolating);
}

std::uint32_t IkRequest::continue_solution_check(std::uint32_t units) {
  std::uint32_t spent = 0;
  if (!model_.uncertainty.evaluation_finished(solution_check_)) {
    spent = model_.uncertainty.continue_evaluation(solution_check_, units);
  }
  if (!model_.uncertainty.evaluation_finished(solution_check_) || spent + kWorkCosts.ik_finish > units) return spent;
  if (model_.uncertainty.evaluation_result(solution_check_).extrapolating) {
    retry_or_refuse(checked_joints_);
  } else {
    conclude(true, checked_joints_);
  }
  return spent + kWorkCosts.ik_finish;
}

void IkRequest::end(protocol::IkOutcome outcome) {
  fill_report(outcome);
  solving_ = false;
  checking_solution_ = false;
  publish_report();
}

// The frames are encoded here, where each length is checked, and kept for
// publish_setpoints().
bool IkRequest::set_setpoints(const Joints& joints) {
  Cables cables;
  if (model::cables_from_joints(commanded_joints(model_, joints), model_.geometry, cables) != model::Status::ok) {
    return false;
  }
  // The joints are the effective lengths'; the drives are sent what makes them.
  if (hysteresis_ != nullptr) hysteresis_->commanded_for(cables);
  // One CABLE_SETPOINT per segment, or on an FD bus four segments a
  // CABLE_SETPOINTS_FD frame.
  hal::CanFrame frames[kMaxSegments];
  const int segments = model_.geometry.segment_count;
  int frame_count = 0;
  if (outbox_.drives_fd()) {
    constexpr int kPerFrame = protocol::cable_setpoints_fd::kSegmentsPerFrame;
    for (int index = 0, first = 0; index * kPerFrame < segments; ++index) {
      protocol::CableSetpointsFd setpoints;
      setpoints.index = index;
      for (int s = index * kPerFrame; s < segments && s < (index + 1) * kPerFrame; ++s) {
        const int count = model_.geometry.segments[s].cables.count;
        setpoints.segments[setpoints.segment_count++] =
            protocol::segment_cables_frame<protocol::CableSetpoint>(s, cables, first, count);
        first += count;
      }
      if (!protocol::encode(setpoints, frames[frame_count++])) return false;
    }
  } else {
    for (int s = 0, first = 0; s < segments; first += model_.geometry.segments[s].cables.count, ++s) {
      const auto setpoint = protocol::segment_cables_frame<protocol::CableSetpoint>(
          s, cables, first, model_.geometry.segments[s].cables.count);
      if (!protocol::encode(setpoint, frames[frame_count++])) return false;
    }
  }
  for (int k = 0; k < frame_count; ++k) setpoint_frames_[k] = frames[k];
  setpoint_frame_count_ = frame_count;
  setpoints_mm_ = cables;
  setpoint_joints_ = joints;
  has_setpoints_ = true;
  return true;
}

void IkRequest::publish_setpoints() {
  if (drives_ != nullptr) {
    double setpoints_mm[model::kMaxCables];
    const int cables = model_.geometry.cable_count();
    for (int k = 0; k < cables; ++k) setpoints_mm[k] = double(setpoints_mm_[k]);
    // Drives that do not take them (not ready, a length beyond a drive's
    // range) say so in their health, which the runtime reports.
    drives_->command(setpoints_mm, cables);
    setpoints_published_ += 1;
    return;
  }
  for (int k = 0; k < setpoint_frame_count_; ++k) outbox_.send_to_drives(setpoint_frames_[k]);
  setpoints_published_ += 1;
}

void IkRequest::publish_report() {
  const IkReport& r = report_;
  hal::CanFrame frame;
  protocol::encode(protocol::IkReport{r.sequence, r.outcome, r.iterations, r.cycles, double(r.position_error_mm),
                                      double(r.orientation_error_rad)},
                   frame);
  outbox_.send(frame);
}

}  // namespace cdcr::firmware
