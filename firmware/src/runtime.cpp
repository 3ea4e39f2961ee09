#include "cdcr/firmware/runtime.hpp"

#include <cmath>

#include <Eigen/Geometry>

namespace cdcr::firmware {

namespace {

std::int64_t to_us(std::int64_t ns) { return (ns + 500) / 1000; }

// The drives report cable lengths in the protocol's steps: a segment at its
// bending limit may read one step beyond it.
constexpr Scalar kCableResolutionMm = Scalar(protocol::kLengthScaleMm);

// Hamilton quaternion, w first, with w >= 0 so each rotation has one encoding.
protocol::PoseOrientation orientation_frame(const model::Mat3<Scalar>& rotation) {
  Eigen::Quaternion<Scalar> quaternion(rotation);
  quaternion.normalize();
  const double sign = quaternion.w() < 0 ? -1.0 : 1.0;
  return {sign * quaternion.w(), sign * quaternion.x(), sign * quaternion.y(), sign * quaternion.z()};
}

// Console lines built without printf: newlib's formatted output allocates,
// and a board build links no heap.
class LogLine {
 public:
  LogLine& operator<<(const char* text) {
    while (*text != '\0' && length_ + 1 < kConsoleLineBytes) text_[length_++] = *text++;
    text_[length_] = '\0';
    return *this;
  }
  LogLine& operator<<(unsigned value) {
    char digits[10];
    int count = 0;
    do {
      digits[count++] = static_cast<char>('0' + value % 10);
      value /= 10;
    } while (value != 0);
    while (count > 0 && length_ + 1 < kConsoleLineBytes) text_[length_++] = digits[--count];
    text_[length_] = '\0';
    return *this;
  }
  const char* c_str() const { return text_; }

 private:
  char text_[kConsoleLineBytes] = {};
  int length_ = 0;
};

}  // namespace

Runtime::Runtime(const hal::Hal& hal, const Geometry& fallback_geometry)
    : hal_(hal), fallback_geometry_(fallback_geometry), geometry_(fallback_geometry), update_(hal.flash, hal.can) {}

RuntimeState Runtime::init() {
  state_ = RuntimeState::boot;
  static constexpr hal::CanFilter kFilters[] = {protocol::kCableFeedbackFrames, protocol::kTargetFrames,
                                                protocol::kPayloadFrames, protocol::kUpdateRequestFrames};
  static_assert(sizeof(kFilters) / sizeof(kFilters[0]) <= kMaxCanFilters, "more filters than a controller must offer");
  // The model update's frames only where there is a flash to write them to.
  const std::size_t filter_count = sizeof(kFilters) / sizeof(kFilters[0]) - (update_.enabled() ? 0 : 1);
  can_filters_accepted_ = hal_.can.set_filters(kFilters, filter_count);

  boot_fault_ = FaultCode::none;
  boot_fault_detail_ = FaultDetail();
  const SlotImage source = model_source();
  const hal::MemoryRegion region = source.region;
  geometry_ = fallback_geometry_;
  if (region.data == nullptr || region.size_bytes == 0) {
    boot_fault_ = FaultCode::image_missing;
  } else {
    const model::ImageStatus parsed = parse_model(source, image_);
    if (parsed != model::ImageStatus::ok) {
      boot_fault_ = FaultCode::image_invalid;
      boot_fault_detail_ = FaultDetail(parsed);
    } else if (const model::Status s = model::geometry_from_image(image_, geometry_); s != model::Status::ok) {
      geometry_ = fallback_geometry_;
      boot_fault_ = FaultCode::image_geometry_invalid;
      boot_fault_detail_ = FaultDetail(s);
    } else if (const model::Status b = correction_.bind(image_); b != model::Status::ok) {
      geometry_ = fallback_geometry_;
      boot_fault_ = FaultCode::image_geometry_invalid;
      boot_fault_detail_ = FaultDetail(b);
    } else if (const model::Status u = uncertainty_.bind(image_); u != model::Status::ok) {
      geometry_ = fallback_geometry_;
      boot_fault_ = FaultCode::image_geometry_invalid;
      boot_fault_detail_ = FaultDetail(u);
    }
  }
  if (geometry_.validate() != model::Status::ok) {
    // Not even the fallback is usable: nothing can be estimated, so the
    // runtime stays silent apart from its heartbeat.
    boot_fault_ = FaultCode::image_geometry_invalid;
    mode_ = RuntimeState::degraded;
    enter(RuntimeState::fault);
    return state_;
  }
  mode_ = boot_fault_ == FaultCode::none ? RuntimeState::run : RuntimeState::degraded;
  // A payload received before init stays; otherwise the image's default.
  if (payload_received_) {
    correction_.set_payload_kg(payload_kg_);
  } else {
    payload_kg_ = correction_.payload_kg();
  }
  latest_cables_mm_.setZero(4 * geometry_.segment_count);
  model::IkSolverOptions<Scalar> solver_options;
  solver_options.max_corrections = kMaxIkCorrections;
  solver_options.max_iterations = kMaxIkIterations;
  // In DEGRADED the same solver solves the nominal model.
  solver_.configure(geometry_, mode_ == RuntimeState::run ? &solver_correction_ : nullptr, solver_options,
                    kIkWorkCosts);
  // The forward path spends one unit per training point and the overhead,
  // a cycle with a slice of the variance that too; IK gets the rest.
  const bool with_variance = mode_ == RuntimeState::run && uncertainty_.has_variance();
  // A payload model's points cost more units each (work_costs.hpp), and
  // IK's smallest step may then be a block of its gradient.
  const bool compensated = mode_ == RuntimeState::run;
  const std::uint32_t forward_units =
      kWorkCosts.cycle_overhead + (compensated ? correction_.training_points() * correction_.mean_point_units() : 0);
  const std::uint32_t min_ik_units =
      compensated && correction_.smallest_gradient_slice_units() > kMinIkUnitsPerCycle
          ? correction_.smallest_gradient_slice_units()
          : kMinIkUnitsPerCycle;
  const auto ik_share = [min_ik_units](std::uint32_t used) {
    return used + min_ik_units < kCycleWorkUnits ? kCycleWorkUnits - used : min_ik_units;
  };
  ik_units_alone_ = ik_share(forward_units);
  ik_units_beside_variance_ = ik_share(forward_units + (with_variance ? kUncertaintyUnitsPerCycle : 0));
  ik_units_per_cycle_ = ik_units_beside_variance_;
  // A large model leaves no room for a slice beside IK's smallest step:
  // then the variance waits while a target is solved.
  variance_beside_ik_ = forward_units + kUncertaintyUnitsPerCycle + min_ik_units <= kCycleWorkUnits;
  enter(mode_);
  if (boot_fault_ != FaultCode::none) {
    LogLine line;
    line << "fault: " << to_string(boot_fault_) << " (detail " << unsigned(boot_fault_detail_.wire_value()) << ")";
    hal_.console.write_line(line.c_str());
  }
  if (!can_filters_accepted_) {
    LogLine line;
    line << "fault: " << to_string(FaultCode::can_filters_refused) << ", receiving unfiltered";
    hal_.console.write_line(line.c_str());
  }
  return state_;
}

FaultCode Runtime::active_fault() const {
  if (state_ == RuntimeState::fault) return FaultCode::cable_input_stale;
  if (unreported_event_ != FaultCode::none) return unreported_event_;
  if (boot_fault_ != FaultCode::none) return boot_fault_;
  return can_filters_accepted_ ? FaultCode::none : FaultCode::can_filters_refused;
}

FaultDetail Runtime::active_fault_detail() const {
  const FaultCode fault = active_fault();
  if (fault == FaultCode::none) return FaultDetail();
  if (fault == unreported_event_) return last_event_detail_;
  if (fault == boot_fault_) return boot_fault_detail_;
  return FaultDetail();
}

model::Status Runtime::estimate_pose(const Cables& cables_mm, PoseEstimate& estimate) const {
  if (mode_ == RuntimeState::run) {
    model::ForwardResult<Scalar, kMaxSegments> result;
    if (const model::Status s =
            model::compensated_forward(cables_mm, geometry_, correction_, result, kCableResolutionMm);
        s != model::Status::ok) {
      return s;
    }
    estimate.pose = result.compensated;
    estimate.joints = result.joints;
    estimate.compensated = true;
    correction_.kernel_coordinates(model::bend_from_joints(result.joints), estimate.kernel_coordinates);
    estimate.outside_range = uncertainty_.outside_range(estimate.kernel_coordinates);
    return model::Status::ok;
  }
  Joints joints;
  if (const model::Status s = model::joints_from_cables(cables_mm, geometry_, joints, kCableResolutionMm);
      s != model::Status::ok) {
    return s;
  }
  estimate.pose = model::forward_kinematics_bend(model::bend_from_joints(joints), geometry_);
  estimate.joints = joints;
  estimate.compensated = false;
  estimate.outside_range = false;
  return model::Status::ok;
}

model::PoseUncertainty<Scalar> Runtime::estimate_uncertainty(const PoseEstimate& estimate) const {
  if (!estimate.compensated || !uncertainty_.bound()) return model::PoseUncertainty<Scalar>{};
  return uncertainty_.evaluate(estimate.kernel_coordinates, estimate.pose.position_mm);
}

bool Runtime::extrapolating() const {
  return has_pose_ && (latest_pose_.outside_range || (has_uncertainty_ && latest_uncertainty_.extrapolating));
}

void Runtime::run_cycle(const hal::TimerTick& tick) {
  const std::int64_t start_ns = hal_.clock.now_ns();
  ++cycle_;
  fresh_cables_ = false;
  ik_units_last_cycle_ = 0;

  hal::CanFrame frame;
  for (int i = 0; i < kMaxRxFramesPerCycle && hal_.can.receive(frame) == hal::CanStatus::ok; ++i) handle_frame(frame);

  if (state_ != RuntimeState::boot) update_pose();
  // While a target is solved, the variance gets a slice every few cycles
  // only: IK's latency is what a user waits on.
  const bool variance_slice =
      uncertainty_running_ &&
      (!solving_ || (variance_beside_ik_ && cycle_ % kUncertaintyEveryCyclesWhileSolving == 0));
  if (variance_slice) continue_uncertainty();
  ik_units_per_cycle_ = variance_slice ? ik_units_beside_variance_ : ik_units_alone_;
  if (cycle_ % kStatusEveryCycles == 0) publish_status();
  // The update's work comes out of IK's share, short of IK's smallest step;
  // a verification that gets nothing from that has a turn of its own every
  // few cycles (capacity.hpp).
  std::uint32_t ik_floor = solving_ ? kMinIkUnitsPerCycle : 0;
  const bool update_turn = solving_ && update_.verifying() &&
                           ik_units_per_cycle_ < ik_floor + kUpdateStepUnits + kUpdateHashUnitsPer64Bytes &&
                           cycle_ % kUpdateTurnEveryCyclesWhileSolving == 0;
  if (update_turn) ik_floor = 0;
  const std::uint32_t update_units =
      update_.step(cycle_, geometry_, ik_units_per_cycle_ > ik_floor ? ik_units_per_cycle_ - ik_floor : 0);
  ik_units_per_cycle_ = ik_units_per_cycle_ > update_units + ik_floor ? ik_units_per_cycle_ - update_units : ik_floor;
  if (update_.switch_pending()) reload_model();
  // IK last: the pose, STATUS and the staleness check never wait for it.
  if (solving_ && !update_turn) continue_solve();

  const std::int64_t end_ns = hal_.clock.now_ns();
  const std::int64_t execution_ns = end_ns - start_ns;
  const std::int64_t jitter_ns = start_ns - tick.release_ns;
  statistics_.cycles += 1;
  statistics_.execution_total_ns += execution_ns;
  if (execution_ns > statistics_.execution_max_ns) statistics_.execution_max_ns = execution_ns;
  if (jitter_ns > statistics_.jitter_max_ns) statistics_.jitter_max_ns = jitter_ns;
  statistics_.overruns += tick.missed_releases;
  if (execution_ns > hal_.timer.period_ns() && hal_.timer.period_ns() > 0) statistics_.overruns += 1;
}

void Runtime::handle_frame(const hal::CanFrame& frame) {
  if (protocol::cable_feedback::kMessage.carries(frame.id)) {
    handle_cable_frame(frame);
  } else if (protocol::target_orientation::kMessage.carries(frame.id)) {
    handle_target_orientation(frame);
  } else if (protocol::target_position_xy::kMessage.carries(frame.id)) {
    handle_target_position(frame);
  } else if (protocol::target_position_z::kMessage.carries(frame.id)) {
    handle_target_commit(frame);
  } else if (protocol::payload::kMessage.carries(frame.id)) {
    handle_payload(frame);
  } else if (ModelUpdate::carries(frame.id)) {
    update_.handle_frame(frame, cycle_);
  }
  // Anything else is another node's traffic: the unused id the target
  // filter passes, or everything when the controller refused the filters.
}

void Runtime::handle_cable_frame(const hal::CanFrame& frame) {
  protocol::CableFeedback feedback;
  if (protocol::decode(frame, feedback) != protocol::DecodeStatus::ok ||
      feedback.segment >= geometry_.segment_count) {
    reject_frame(FaultCode::cable_frame_malformed);
    return;
  }
  const int segment = feedback.segment;
  for (int k = 0; k < 4; ++k) latest_cables_mm_[4 * segment + k] = static_cast<Scalar>(feedback.lengths_mm[k]);
  segment_updated_cycle_[segment] = cycle_;
  segment_seen_[segment] = true;
  fresh_cables_ = true;
}

// A malformed part of a target drops what was pending of that part, so the
// commit that follows is refused rather than solved with an older part.
void Runtime::handle_target_orientation(const hal::CanFrame& frame) {
  has_pending_orientation_ = protocol::decode(frame, pending_orientation_) == protocol::DecodeStatus::ok;
  if (!has_pending_orientation_) reject_frame(FaultCode::target_malformed);
}

void Runtime::handle_target_position(const hal::CanFrame& frame) {
  has_pending_position_ = protocol::decode(frame, pending_position_) == protocol::DecodeStatus::ok;
  if (!has_pending_position_) reject_frame(FaultCode::target_malformed);
}

void Runtime::handle_payload(const hal::CanFrame& frame) {
  protocol::Payload payload;
  if (protocol::decode(frame, payload) != protocol::DecodeStatus::ok) {
    reject_frame(FaultCode::payload_invalid);
    return;
  }
  set_payload_kg(static_cast<Scalar>(payload.payload_kg));
}

bool Runtime::set_payload_kg(Scalar payload_kg) {
  const protocol::SignalSpec& signal = protocol::payload::kPayload;
  if (!(payload_kg >= Scalar(signal.minimum) && payload_kg <= Scalar(signal.maximum))) {  // NaN fails both
    record_event(FaultCode::payload_invalid);
    return false;
  }
  payload_kg_ = payload_kg;
  payload_received_ = true;
  correction_.set_payload_kg(payload_kg);
  return true;
}

// A segment's cables are used for a pose until they are stale (the same
// limit as input_stale()), so segments reporting in different cycles still
// make a set, and every cycle in RUN has a pose.
bool Runtime::segment_current(int segment) const {
  return segment_seen_[segment] && cycle_ - segment_updated_cycle_[segment] <= std::uint32_t(kStaleInputCycles);
}

// Stale: one segment silent, or no valid cable set, for more than
// kStaleInputCycles (a segment that never reported counts from boot).
bool Runtime::input_stale() const {
  if (cycle_ - last_valid_cycle_ > std::uint32_t(kStaleInputCycles)) return true;
  for (int s = 0; s < geometry_.segment_count; ++s) {
    if (cycle_ - segment_updated_cycle_[s] > std::uint32_t(kStaleInputCycles)) return true;
  }
  return false;
}

void Runtime::update_pose() {
  bool complete = fresh_cables_;
  for (int s = 0; s < geometry_.segment_count && complete; ++s) complete = segment_current(s);
  if (complete) {
    PoseEstimate estimate;
    if (const model::Status s = estimate_pose(latest_cables_mm_, estimate); s == model::Status::ok) {
      latest_pose_ = estimate;
      has_pose_ = true;
      last_valid_cycle_ = cycle_;
      if (state_ == RuntimeState::fault) {
        enter(mode_);
      }
      publish_pose();
      if (!uncertainty_running_ && latest_pose_.compensated && uncertainty_.has_variance()) {
        uncertainty_.begin_evaluation(latest_pose_.kernel_coordinates, latest_pose_.pose.position_mm,
                                      uncertainty_evaluation_);
        uncertainty_running_ = true;
        uncertainty_running_sequence_ = static_cast<std::uint8_t>(cycle_ & 0xFF);
      }
    } else {
      statistics_.rejected_cable_sets += 1;
      record_event(FaultCode::cable_lengths_invalid, FaultDetail(s));
    }
  }
  if (state_ != RuntimeState::fault && input_stale()) {
    statistics_.stale_events += 1;
    enter(RuntimeState::fault);
    if (solving_) end_solve(protocol::IkOutcome::aborted_fault);
  }
}

void Runtime::handle_target_commit(const hal::CanFrame& frame) {
  statistics_.targets_received += 1;
  protocol::TargetPositionZ commit;
  const bool well_formed = protocol::decode(frame, commit) == protocol::DecodeStatus::ok;
  last_ik_report_ = IkReport{};
  // Even a malformed commit is answered with its sequence, if it has one.
  last_ik_report_.sequence = well_formed ? commit.sequence : protocol::commit_sequence(frame);

  Pose target;
  bool valid = well_formed && has_pending_position_;
  if (valid) {
    target.position_mm = model::Vec3<Scalar>(Scalar(pending_position_.x_mm), Scalar(pending_position_.y_mm),
                                             Scalar(commit.z_mm));
  }
  if (valid && commit.mode == protocol::TargetMode::pose) {
    const protocol::TargetOrientation& q = pending_orientation_;
    const double norm = std::sqrt(q.qw * q.qw + q.qx * q.qx + q.qy * q.qy + q.qz * q.qz);
    valid = has_pending_orientation_ && std::abs(norm - 1.0) <= protocol::kQuaternionNormTolerance;
    if (valid) {
      target.rotation = Eigen::Quaternion<Scalar>(Scalar(q.qw / norm), Scalar(q.qx / norm), Scalar(q.qy / norm),
                                                  Scalar(q.qz / norm))
                            .toRotationMatrix();
    }
  }
  has_pending_position_ = false;
  has_pending_orientation_ = false;

  if (!valid) {
    reject_frame(FaultCode::target_malformed);
    last_ik_report_.outcome = protocol::IkOutcome::rejected_malformed;
  } else if (state_ == RuntimeState::fault || state_ == RuntimeState::boot) {
    last_ik_report_.outcome = protocol::IkOutcome::rejected_state;
  } else {
    start_solve(target, commit);
    return;  // reported when it ends
  }
  publish_ik_report();
}

void Runtime::publish_pose() {
  const Pose& pose = latest_pose_.pose;
  hal::CanFrame frame;
  protocol::encode(protocol::PosePositionXy{pose.position_mm.x(), pose.position_mm.y()}, frame);
  send(frame);
  protocol::encode(protocol::PosePositionZ{pose.position_mm.z(), latest_pose_.compensated,
                                           static_cast<std::uint8_t>(cycle_ & 0xFF), extrapolating()},
                   frame);
  send(frame);
  protocol::encode(orientation_frame(pose.rotation), frame);
  send(frame);
  statistics_.poses_published += 1;
}

// A slice of the variance's work; when it ends, its radii go out.
void Runtime::continue_uncertainty() {
  uncertainty_.continue_evaluation(uncertainty_evaluation_, kUncertaintyUnitsPerCycle);
  if (!uncertainty_.evaluation_finished(uncertainty_evaluation_)) return;
  uncertainty_running_ = false;
  latest_uncertainty_ = uncertainty_.evaluation_result(uncertainty_evaluation_);
  has_uncertainty_ = true;
  uncertainty_sequence_ = uncertainty_running_sequence_;
  if (state_ == RuntimeState::fault) return;
  protocol::PoseUncertainty message;
  message.r95_position_mm = latest_uncertainty_.r95_mm;
  message.r95_orientation_deg = latest_uncertainty_.r95_deg;
  message.latent_share = latest_uncertainty_.latent_share;
  message.extrapolating = latest_uncertainty_.extrapolating;
  message.outside_range = latest_uncertainty_.outside_range;
  message.sequence = uncertainty_sequence_;
  hal::CanFrame frame;
  protocol::encode(message, frame);
  send(frame);
}

void Runtime::publish_status() {
  // Both read before sending: a failed send records an event of its own.
  const FaultCode fault = active_fault();
  const FaultDetail detail = active_fault_detail();
  protocol::Status status;
  status.state = state_;
  status.extrapolating = extrapolating();
  status.fault = fault;
  status.overruns = statistics_.overruns;
  status.exec_max_us = to_us(statistics_.execution_max_ns);
  status.exec_mean_us = to_us(statistics_.execution_mean_ns());
  hal::CanFrame frame;
  protocol::encode(status, frame);
  send(frame);

  protocol::Stats stats;
  stats.jitter_max_us = to_us(statistics_.jitter_max_ns);
  stats.rejected_frames = std::int64_t(statistics_.rejected_frames) + statistics_.rejected_cable_sets;
  stats.cycle_count = static_cast<std::uint16_t>(statistics_.cycles & 0xFFFF);
  stats.fault_detail = detail;
  stats.stale_events = statistics_.stale_events;
  protocol::encode(stats, frame);
  send(frame);
  unreported_event_ = FaultCode::none;
}

void Runtime::send(const hal::CanFrame& frame) {
  if (hal_.can.send(frame) != hal::CanStatus::ok) record_event(FaultCode::can_transmit_failed);
}

void Runtime::record_event(FaultCode code, FaultDetail detail) {
  last_event_ = unreported_event_ = code;
  last_event_detail_ = detail;
}

void Runtime::reject_frame(FaultCode code) {
  statistics_.rejected_frames += 1;
  record_event(code);
}

void Runtime::enter(RuntimeState next) {
  if (next == state_) return;
  state_ = next;
  LogLine line;
  line << "state " << to_string(next);
  hal_.console.write_line(line.c_str());
}

model::Status SolverCorrection::begin_evaluation(const Joints& bend, Evaluation& evaluation,
                                               bool with_gradient) const {
  return correction_->begin_evaluation(bend, evaluation, with_gradient);
}

std::uint32_t SolverCorrection::continue_evaluation(Evaluation& evaluation, std::uint32_t max_units) const {
  return correction_->continue_evaluation(evaluation, max_units);
}

bool SolverCorrection::evaluation_finished(const Evaluation& evaluation) const {
  return correction_->evaluation_finished(evaluation);
}

bool SolverCorrection::evaluation_has_gradient(const Evaluation& evaluation) const {
  return correction_->evaluation_has_gradient(evaluation);
}

void SolverCorrection::evaluation_result(const Evaluation& evaluation, model::Twist<Scalar>& eps,
                                         model::Jacobian<Scalar, kMaxSegments>& d_eps_d_bend) const {
  correction_->evaluation_result(evaluation, eps, d_eps_d_bend);
}

}  // namespace cdcr::firmware
