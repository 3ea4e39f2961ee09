#include "cdcr/firmware/runtime.hpp"

#include <cmath>

#include <Eigen/Geometry>

#include "cdcr/firmware/console_line.hpp"
#include "cdcr/firmware/model_loader.hpp"
#include "cdcr/model/unit_quaternion.hpp"

namespace cdcr::firmware {

namespace {

std::int64_t to_us(std::int64_t ns) { return (ns + 500) / 1000; }

protocol::PoseOrientation orientation_frame(const model::Mat3<Scalar>& rotation) {
  const Eigen::Quaternion<Scalar> quaternion = model::canonical_quaternion(rotation);
  return {quaternion.w(), quaternion.x(), quaternion.y(), quaternion.z()};
}

}  // namespace

Runtime::Runtime(const hal::Hal& hal, const Geometry& fallback_geometry)
    : hal_(hal),
      fallback_geometry_(fallback_geometry),
      host_bus_(hal.can),
      drives_bus_(hal.drives_can != nullptr ? *hal.drives_can : hal.can),
      outbox_(host_bus_, drives_bus_),
      update_(hal.flash, host_bus_) {
  model_.geometry = fallback_geometry;
  ik_.set_drives(hal.drives);
}

RuntimeState Runtime::init() {
  state_ = RuntimeState::boot;
  // The host's inputs, the model update's frames last (only where there is
  // a flash to write them to), and the drives' feedback: on the host's bus
  // too without a bus of their own.
  static constexpr hal::CanFilter kFilters[] = {protocol::kCableFeedbackFrames, protocol::kTargetFrames,
                                                protocol::kPayloadFrames, protocol::kUpdateRequestFrames};
  static_assert(sizeof(kFilters) / sizeof(kFilters[0]) <= kMaxCanFilters, "more filters than a controller must offer");
  const hal::CanFilter* host_filters = kFilters;
  std::size_t host_filter_count = sizeof(kFilters) / sizeof(kFilters[0]) - (update_.enabled() ? 0 : 1);
  can_filters_accepted_ = true;
  if (hal_.drives != nullptr) {
    // The drives' buses are the backend's; CABLE_FEEDBACK is not taken.
    ++host_filters;
    --host_filter_count;
    can_filters_accepted_ = hal_.drives->start();
  } else if (has_drives_bus()) {
    ++host_filters;
    --host_filter_count;
    can_filters_accepted_ = drives_bus_.set_filters(kFilters, 1);
  }
  can_filters_accepted_ = host_bus_.set_filters(host_filters, host_filter_count) && can_filters_accepted_;

  const BootFault boot = load_model(update_, hal_.model_storage, fallback_geometry_, model_);
  boot_fault_ = boot.code;
  boot_fault_detail_ = boot.detail;
  if (model_.geometry.validate() != model::Status::ok) {
    // Not even the fallback is usable: nothing can be estimated, so the
    // runtime stays silent apart from its heartbeat.
    boot_fault_ = FaultCode::image_geometry_invalid;
    model_.compensated = false;
    enter(RuntimeState::fault);
    return state_;
  }
  model_.compensated = boot_fault_ == FaultCode::none;
  // A payload received before init stays; otherwise the image's default.
  if (payload_received_) {
    model_.correction.set_payload_kg(payload_kg_);
  } else {
    payload_kg_ = model_.correction.payload_kg();
  }
  latest_cables_mm_.setZero(model_.geometry.cable_count());
  ik_.configure();
  hysteresis_.bind(model_);
  scheduler_.configure({model_.compensated, model_.uncertainty.has_variance(),
                        model_.correction.training_points() * model_.correction.mean_point_units(),
                        model_.correction.smallest_gradient_slice_units(), hysteresis_units(hysteresis_),
                        model_.compliance.empty() ? 0 : kComplianceUnits,
                        hal_.drives != nullptr ? kWorkCosts.drive * std::uint32_t(hal_.drives->drive_count()) : 0});
  enter(mode());
  if (boot_fault_ != FaultCode::none) {
    ConsoleLine line;
    line << "fault: " << to_string(boot_fault_) << " (detail " << unsigned(boot_fault_detail_.wire_value()) << ")";
    hal_.console.write_line(line.c_str());
  }
  if (!can_filters_accepted_) {
    ConsoleLine line;
    line << "fault: " << to_string(FaultCode::can_filters_refused) << ", receiving unfiltered";
    hal_.console.write_line(line.c_str());
  }
  return state_;
}

FaultCode Runtime::active_fault() const {
  if (state_ == RuntimeState::fault && drives_failed()) {
    switch (drives_health_.condition) {
      case hal::DrivesCondition::silent: return FaultCode::drive_silent;
      case hal::DrivesCondition::refused: return FaultCode::drive_refused;
      default: return FaultCode::drive_fault;
    }
  }
  if (state_ == RuntimeState::fault) return FaultCode::cable_input_stale;
  if (outbox_.unreported_event() != FaultCode::none) return outbox_.unreported_event();
  if (boot_fault_ != FaultCode::none) return boot_fault_;
  return can_filters_accepted_ ? FaultCode::none : FaultCode::can_filters_refused;
}

FaultDetail Runtime::active_fault_detail() const {
  const FaultCode fault = active_fault();
  if (fault == FaultCode::none) return FaultDetail();
  if (detail_kind(fault) == FaultDetailKind::drive_node) return FaultDetail::drive(drives_health_.drive);
  if (fault == outbox_.unreported_event()) return outbox_.last_event_detail();
  if (fault == boot_fault_) return boot_fault_detail_;
  return FaultDetail();
}

bool Runtime::extrapolating() const {
  const bool range_flags = latest_pose_.outside_range && model_.uncertainty.range_flags();
  return has_pose_ && (range_flags || (has_uncertainty() && latest_uncertainty().extrapolating));
}

void Runtime::run_cycle(const hal::TimerTick& tick, CycleInputs* inputs) {
  const std::int64_t start_ns = hal_.clock.now_ns();
  ++cycle_;
  if (pose_wait_ > 0) --pose_wait_;
  if (variance_wait_ > 0) --variance_wait_;
  ik_units_last_cycle_ = 0;

  const int delivered = inputs != nullptr ? inputs->deliver(*this) : 0;
  receive_frames(host_bus_, delivered);
  if (hal_.drives != nullptr) {
    receive_drive_lengths();
  } else if (has_drives_bus()) {
    receive_frames(drives_bus_, 0);
  }

  if (state_ != RuntimeState::boot) update_pose();
  fresh_cables_ = false;
  const CyclePlan plan = scheduler_.plan(cycle_, variance_.running(), ik_.running(), update_.verifying());
  if (plan.variance_slice && variance_.continue_slice(model_.uncertainty)) {
    hysteresis_.widen(model_, variance_.result());
    publish_uncertainty();
  }
  if (cycle_ % std::uint32_t(publish_rates_.status_every) == 0) publish_status();
  scheduler_.charge_update(update_.step(cycle_, model_.geometry, plan.update_offer));
  if (update_.switch_pending()) reload_model();
  // IK last: the pose, STATUS and the staleness check never wait for it.
  if (ik_.running() && !plan.update_turn && (state_ == RuntimeState::run || state_ == RuntimeState::degraded)) {
    ik_units_last_cycle_ = ik_.continue_slice(scheduler_.ik_units());
  }
  // The drives' frames of this cycle (their setpoints, their SYNC) last.
  if (hal_.drives != nullptr) hal_.drives->transmit();

  statistics_.record_cycle(tick, start_ns, hal_.clock.now_ns(), hal_.timer.period_ns());
}

// A bus's frames of this cycle, after `frames` already counted against its bound.
void Runtime::receive_frames(hal::CanBus& bus, int frames) {
  hal::CanFrame frame;
  for (; frames < kMaxRxFramesPerCycle && bus.receive(frame) == hal::CanStatus::ok; ++frames) handle_frame(frame);
}

// The drives' lengths of this cycle, and their health: a failure takes the
// runtime to FAULT, named on the console once.
void Runtime::receive_drive_lengths() {
  hal::Drives& drives = *hal_.drives;
  drives.receive();
  const bool was_failed = drives_failed();
  drives_health_ = drives.health();
  if (drives_failed()) {
    if (!was_failed) report_drives_fault();
    if (state_ != RuntimeState::fault && state_ != RuntimeState::boot) {
      enter(RuntimeState::fault);
      if (ik_.running()) ik_.end(protocol::IkOutcome::aborted_fault);
    }
    return;
  }
  const int cables = model_.geometry.cable_count();
  double lengths_mm[model::kMaxCables];
  if (!drives.lengths(lengths_mm, cables)) return;
  for (int s = 0; s < model_.geometry.segment_count; ++s) {
    Scalar segment_mm[4] = {};
    const int first = model_.geometry.first_cable(s);
    for (int k = 0; k < model_.geometry.segments[s].cables.count; ++k) segment_mm[k] = Scalar(lengths_mm[first + k]);
    set_cable_lengths(s, segment_mm);
  }
}

// Out of line: the cycle's code stays small on the boards (the M7's code
// budget), and a fault is reported once.
[[gnu::noinline]] void Runtime::report_drives_fault() const {
  ConsoleLine line;
  line << "fault: " << hal_.drives->describe(drives_health_.kind) << ", drive " << unsigned(drives_health_.drive)
       << " (cable " << int(drives_health_.cable) << "), detail " << unsigned(drives_health_.detail);
  hal_.console.write_line(line.c_str());
}

bool Runtime::recover_drives() {
  if (hal_.drives == nullptr || !hal_.drives->recover()) return false;
  drives_health_ = hal_.drives->health();
  return true;
}

// Between two cycles' work: the request being solved was for the old
// model, and the variance in progress too. The cables received so far stay.
void Runtime::reload_model() {
  if (ik_.running()) ik_.end(protocol::IkOutcome::superseded);
  variance_.abandon();
  const Cables cables_mm = latest_cables_mm_;
  const int segments = model_.geometry.segment_count;
  init();
  if (model_.geometry.segment_count == segments) latest_cables_mm_ = cables_mm;
}

void Runtime::handle_frame(const hal::CanFrame& frame) {
  // The update's frames first: one mask test, where a transfer's cycle
  // brings tens of them and would test each against every input first.
  if (ModelUpdate::carries(frame.id)) {
    update_.handle_frame(frame, cycle_);
    return;
  }
  // With a Drives backend a CABLE_FEEDBACK frame is no drive's.
  if (hal_.drives != nullptr &&
      (frame.id & protocol::kCableFeedbackFrames.mask) == protocol::kCableFeedbackFrames.id) {
    return;
  }
  if (frame_inputs_.take(frame, *this)) return;
  // Anything else is another node's traffic: the unused id the target
  // filter passes, or everything when the controller refused the filters.
}

// A segment's cables are used for a pose until they are stale (the same
// limit as input_stale()), so segments reporting in different cycles still
// make a set, and every cycle in RUN has a pose.
// A segment of three cables reads the first three lengths.
bool Runtime::set_cable_lengths(int segment, const Scalar (&lengths_mm)[4]) {
  if (segment < 0 || segment >= model_.geometry.segment_count) return false;
  const int cables = model_.geometry.segments[segment].cables.count;
  for (int k = 0; k < cables; ++k) {
    if (std::isnan(lengths_mm[k])) return false;
  }
  const int first = model_.geometry.first_cable(segment);
  for (int k = 0; k < cables; ++k) latest_cables_mm_[first + k] = lengths_mm[k];
  segment_updated_cycle_[segment] = cycle_;
  segment_seen_[segment] = true;
  fresh_cables_ = true;
  return true;
}

void Runtime::set_target(const TargetRequest& request) {
  statistics_.targets_received += 1;
  frame_inputs_.drop_parts();
  Pose target;
  target.position_mm = model::Vec3<Scalar>(Scalar(request.position_mm[0]), Scalar(request.position_mm[1]),
                                           Scalar(request.position_mm[2]));
  const double* q = request.quaternion;
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!request.well_formed ||
      (request.mode == protocol::TargetMode::pose && !model::is_unit_quaternion_norm(norm))) {
    reject_input(FaultCode::target_malformed);
    ik_.refuse(request.sequence, protocol::IkOutcome::rejected_malformed);
    return;
  }
  if (request.mode == protocol::TargetMode::pose) {
    target.rotation =
        Eigen::Quaternion<Scalar>(Scalar(q[0] / norm), Scalar(q[1] / norm), Scalar(q[2] / norm), Scalar(q[3] / norm))
            .toRotationMatrix();
  }
  if (state_ == RuntimeState::fault || state_ == RuntimeState::boot) {
    ik_.refuse(request.sequence, protocol::IkOutcome::rejected_state);
  } else {
    ik_.start(target, request, has_pose_ ? &latest_pose_ : nullptr);  // reported when it ends
  }
}

bool Runtime::set_payload_kg(Scalar payload_kg) {
  const protocol::SignalSpec& signal = protocol::payload::kPayload;
  if (!(payload_kg >= Scalar(signal.minimum) && payload_kg <= Scalar(signal.maximum))) {  // NaN fails both
    outbox_.record_event(FaultCode::payload_invalid);
    return false;
  }
  payload_kg_ = payload_kg;
  payload_received_ = true;
  model_.correction.set_payload_kg(payload_kg);
  return true;
}

// Stale: one segment silent, or no valid cable set, for more than
// kStaleInputCycles (a segment that never reported counts from boot).
bool Runtime::input_stale() const {
  if (cycle_ - last_valid_cycle_ > std::uint32_t(kStaleInputCycles)) return true;
  for (int s = 0; s < model_.geometry.segment_count; ++s) {
    if (cycle_ - segment_updated_cycle_[s] > std::uint32_t(kStaleInputCycles)) return true;
  }
  return false;
}

void Runtime::update_pose() {
  bool complete = fresh_cables_;
  for (int s = 0; s < model_.geometry.segment_count && complete; ++s) {
    complete = segment_seen_[s] && cycle_ - segment_updated_cycle_[s] <= std::uint32_t(kStaleInputCycles);
  }
  if (complete) {
    PoseEstimate estimate;
    // The hysteresis state moves with every complete set; the pose is that
    // of the effective lengths.
    const Cables& effective_mm = hysteresis_.track(latest_cables_mm_);
    hysteresis_.hold_history(model_.correction);
    if (const model::Status s = estimate_pose(effective_mm, estimate); s == model::Status::ok) {
      latest_pose_ = estimate;
      // IK's corrections take the cables' residuals as last measured.
      model_.correction.set_cable_residuals(estimate.cable_residuals);
      has_pose_ = true;
      last_valid_cycle_ = cycle_;
      if (state_ == RuntimeState::fault && !drives_failed()) enter(mode());
      const bool pose_due = pose_wait_ == 0;
      if (pose_due) {
        publish_pose();
        pose_wait_ = std::uint32_t(publish_rates_.pose_every);
      }
      // Radii are of a pose that went out (POSE_UNCERTAINTY names it by its
      // sequence), at most every uncertainty_every cycles.
      if (pose_due && variance_wait_ == 0 && !variance_.running() && latest_pose_.compensated &&
          model_.uncertainty.has_variance()) {
        variance_.begin(model_.uncertainty, latest_pose_, static_cast<std::uint8_t>(cycle_ & 0xFF));
        hysteresis_.begin_variance(model_, latest_pose_);
        variance_wait_ = std::uint32_t(publish_rates_.uncertainty_every);
      }
    } else {
      statistics_.rejected_cable_sets += 1;
      outbox_.record_event(FaultCode::cable_lengths_invalid, FaultDetail(s));
    }
  }
  if (state_ != RuntimeState::fault && input_stale()) {
    statistics_.stale_events += 1;
    enter(RuntimeState::fault);
    if (ik_.running()) ik_.end(protocol::IkOutcome::aborted_fault);
  }
}

bool Runtime::set_can_formats(hal::CanFormat host, hal::CanFormat drives) {
  if (state_ != RuntimeState::boot || cycle_ != 0) return false;
  if (!has_drives_bus() && host != drives) return false;
  hal::FormattedCanBus probe_host(hal_.can);
  hal::FormattedCanBus probe_drives(has_drives_bus() ? *hal_.drives_can : hal_.can);
  if (!probe_host.set_format(host) || !probe_drives.set_format(drives)) return false;
  host_bus_.set_format(host);
  drives_bus_.set_format(drives);
  return true;
}

bool Runtime::set_publish_rates(const PublishRates& rates) {
  if (!rates.valid()) return false;
  publish_rates_ = rates;
  return true;
}

void Runtime::publish_pose() {
  if (host_bus_.fd()) {
    publish_fd_pose();
    return;
  }
  const Pose& pose = latest_pose_.pose;
  hal::CanFrame frame;
  protocol::encode(protocol::PosePositionXy{pose.position_mm.x(), pose.position_mm.y()}, frame);
  outbox_.send(frame);
  protocol::encode(protocol::PosePositionZ{pose.position_mm.z(), latest_pose_.compensated,
                                           static_cast<std::uint8_t>(cycle_ & 0xFF), extrapolating()},
                   frame);
  outbox_.send(frame);
  protocol::encode(orientation_frame(pose.rotation), frame);
  outbox_.send(frame);
  statistics_.poses_published += 1;
}

// The pose, its flags and the latest radii (of the pose their sequence
// names) in one POSE_FD frame.
void Runtime::publish_fd_pose() {
  const Pose& pose = latest_pose_.pose;
  protocol::PoseFd message;
  message.position_xy = {pose.position_mm.x(), pose.position_mm.y()};
  message.position_z = {pose.position_mm.z(), latest_pose_.compensated, static_cast<std::uint8_t>(cycle_ & 0xFF),
                        extrapolating()};
  message.position_z.radii = has_uncertainty();
  message.orientation = orientation_frame(pose.rotation);
  if (has_uncertainty()) message.uncertainty = uncertainty_frame();
  hal::CanFrame frame;
  protocol::encode(message, frame);
  outbox_.send(frame);
  statistics_.poses_published += 1;
}

protocol::PoseUncertainty Runtime::uncertainty_frame() const {
  const model::PoseUncertainty<Scalar>& radii = variance_.result();
  protocol::PoseUncertainty message;
  message.r95_position_mm = radii.r95_mm;
  message.r95_orientation_deg = radii.r95_deg;
  message.latent_share = radii.latent_share;
  message.extrapolating = radii.extrapolating;
  message.outside_range = radii.outside_range;
  message.sequence = variance_.result_sequence();
  return message;
}

// The radii of a variance that ended this cycle; on an FD bus they go with
// the next POSE_FD.
void Runtime::publish_uncertainty() {
  if (state_ == RuntimeState::fault || host_bus_.fd()) return;
  hal::CanFrame frame;
  protocol::encode(uncertainty_frame(), frame);
  outbox_.send(frame);
}

void Runtime::publish_status() {
  // Both read before sending: a failed send records an event of its own.
  const FaultCode fault = active_fault();
  const FaultDetail detail = active_fault_detail();
  protocol::Status status;
  status.state = state_;
  status.extrapolating = extrapolating();
  status.hysteresis_unknown = !hysteresis_.known();
  status.fault = fault;
  status.overruns = statistics_.overruns;
  status.exec_max_us = to_us(statistics_.execution_max_ns);
  status.exec_mean_us = to_us(statistics_.execution_mean_ns());
  hal::CanFrame frame;
  protocol::encode(status, frame);
  outbox_.send(frame);

  protocol::Stats stats;
  stats.jitter_max_us = to_us(statistics_.jitter_max_ns);
  stats.rejected_frames = std::int64_t(statistics_.rejected_frames) + statistics_.rejected_cable_sets;
  stats.cycle_count = static_cast<std::uint16_t>(statistics_.cycles & 0xFFFF);
  stats.fault_detail = detail;
  stats.stale_events = statistics_.stale_events;
  protocol::encode(stats, frame);
  outbox_.send(frame);
  outbox_.events_reported();
}

void Runtime::reject_input(FaultCode code) {
  statistics_.rejected_frames += 1;
  outbox_.record_event(code);
}

void Runtime::enter(RuntimeState next) {
  if (next == state_) return;
  state_ = next;
  ConsoleLine line;
  line << "state " << to_string(next);
  hal_.console.write_line(line.c_str());
}

}  // namespace cdcr::firmware
