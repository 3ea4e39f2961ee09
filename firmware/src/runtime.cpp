#include "cdcr/firmware/runtime.hpp"

#include <cmath>

#include <Eigen/Geometry>

namespace cdcr::firmware {

namespace {

std::uint16_t saturate_u16(std::int64_t value) {
  if (value < 0) return 0;
  return value > 0xFFFF ? 0xFFFF : static_cast<std::uint16_t>(value);
}

std::int64_t to_us(std::int64_t ns) { return (ns + 500) / 1000; }

// Hamilton quaternion, w first, with w >= 0 so each rotation has one encoding.
void quaternion_of(const model::Mat3<Scalar>& rotation, double (&q)[4]) {
  Eigen::Quaternion<Scalar> quaternion(rotation);
  quaternion.normalize();
  const double sign = quaternion.w() < 0 ? -1.0 : 1.0;
  q[0] = sign * quaternion.w();
  q[1] = sign * quaternion.x();
  q[2] = sign * quaternion.y();
  q[3] = sign * quaternion.z();
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
    : hal_(hal), fallback_geometry_(fallback_geometry), geometry_(fallback_geometry) {}

RuntimeState Runtime::init() {
  state_ = RuntimeState::boot;
  static constexpr hal::CanFilter kFilters[] = {
      {protocol::kCableFeedbackBaseId, 0x7F8},  // 0x100..0x107
      {protocol::kTargetOrientationId, 0x7FC},  // 0x120..0x123
  };
  static_assert(sizeof(kFilters) / sizeof(kFilters[0]) <= kMaxCanFilters, "more filters than a controller must offer");
  hal_.can.set_filters(kFilters, sizeof(kFilters) / sizeof(kFilters[0]));

  const hal::MemoryRegion region = hal_.model_storage.model_region();
  geometry_ = fallback_geometry_;
  if (region.data == nullptr || region.size_bytes == 0) {
    boot_fault_ = FaultCode::image_missing;
  } else {
    model::ImageCapacity capacity;
    capacity.max_training_points = kMaxTrainingPoints;
    capacity.max_segments = kMaxSegments;
    const model::ImageStatus parsed = model::parse_image(region.data, region.size_bytes, image_, capacity);
    if (parsed != model::ImageStatus::ok) {
      boot_fault_ = FaultCode::image_invalid;
      boot_fault_detail_ = static_cast<std::uint8_t>(parsed);
    } else if (const model::Status s = model::geometry_from_image(image_, geometry_); s != model::Status::ok) {
      geometry_ = fallback_geometry_;
      boot_fault_ = FaultCode::image_geometry_invalid;
      boot_fault_detail_ = static_cast<std::uint8_t>(s);
    } else if (const model::Status b = correction_.bind(image_); b != model::Status::ok) {
      geometry_ = fallback_geometry_;
      boot_fault_ = FaultCode::image_geometry_invalid;
      boot_fault_detail_ = static_cast<std::uint8_t>(b);
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
  latest_cables_mm_.setZero(4 * geometry_.segment_count);
  enter(mode_);
  if (boot_fault_ != FaultCode::none) {
    LogLine line;
    line << "fault: " << to_string(boot_fault_) << " (detail " << unsigned(boot_fault_detail_) << ")";
    hal_.console.write_line(line.c_str());
  }
  return state_;
}

FaultCode Runtime::active_fault() const {
  if (state_ == RuntimeState::fault) return FaultCode::cable_input_stale;
  if (unreported_event_ != FaultCode::none) return unreported_event_;
  return boot_fault_;
}

model::Status Runtime::estimate_pose(const Cables& cables_mm, PoseEstimate& estimate) const {
  if (mode_ == RuntimeState::run) {
    model::ForwardResult<Scalar, kMaxSegments> result;
    if (const model::Status s = model::compensated_forward(cables_mm, geometry_, correction_, result);
        s != model::Status::ok) {
      return s;
    }
    estimate.pose = result.compensated;
    estimate.joints = result.joints;
    estimate.compensated = true;
    return model::Status::ok;
  }
  Joints joints;
  if (const model::Status s = model::joints_from_cables(cables_mm, geometry_, joints); s != model::Status::ok) return s;
  estimate.pose = model::forward_kinematics_bend(model::bend_from_joints(joints), geometry_);
  estimate.joints = joints;
  estimate.compensated = false;
  return model::Status::ok;
}

void Runtime::run_cycle(const hal::TimerTick& tick) {
  const std::int64_t start_ns = hal_.clock.now_ns();
  ++cycle_;
  fresh_cables_ = false;

  hal::CanFrame frame;
  for (int i = 0; i < kMaxRxFramesPerCycle && hal_.can.receive(frame) == hal::CanStatus::ok; ++i) handle_frame(frame);

  if (state_ != RuntimeState::boot) update_pose();
  if (cycle_ % kStatusEveryCycles == 0) publish_status();

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
  if (protocol::is_cable_feedback(frame.id)) {
    handle_cable_frame(frame);
    return;
  }
  switch (frame.id) {
    case protocol::kTargetOrientationId: {
      if (frame.dlc != 8) {
        reject_frame(FaultCode::target_malformed);
        return;
      }
      for (int k = 0; k < 4; ++k) pending_quaternion_[k] = protocol::get(frame, protocol::signal::quaternion[k]);
      pending_orientation_ = true;
      return;
    }
    case protocol::kTargetPositionXyId: {
      if (frame.dlc != 8) {
        reject_frame(FaultCode::target_malformed);
        return;
      }
      pending_x_mm_ = protocol::get(frame, protocol::signal::position_xy[0]);
      pending_y_mm_ = protocol::get(frame, protocol::signal::position_xy[1]);
      pending_xy_ = true;
      return;
    }
    case protocol::kTargetPositionZId:
      handle_target_commit(frame);
      return;
    default:
      // Outside what the filters pass: another node's traffic.
      return;
  }
}

void Runtime::handle_cable_frame(const hal::CanFrame& frame) {
  const int segment = static_cast<int>(frame.id - protocol::kCableFeedbackBaseId);
  double lengths_mm[4];
  if (segment >= geometry_.segment_count ||
      protocol::decode_cables(frame, lengths_mm) != protocol::CableFrameStatus::ok) {
    reject_frame(FaultCode::cable_frame_malformed);
    return;
  }
  for (int k = 0; k < 4; ++k) latest_cables_mm_[4 * segment + k] = static_cast<Scalar>(lengths_mm[k]);
  segment_updated_cycle_[segment] = cycle_;
  segment_seen_[segment] = true;
  fresh_cables_ = true;
}

void Runtime::update_pose() {
  bool complete = fresh_cables_;
  for (int s = 0; s < geometry_.segment_count && complete; ++s) {
    complete = segment_seen_[s] && cycle_ - segment_updated_cycle_[s] < std::uint32_t(kStaleInputCycles);
  }
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
    } else {
      statistics_.rejected_cable_sets += 1;
      last_event_ = unreported_event_ = FaultCode::cable_lengths_invalid;
      last_event_detail_ = static_cast<std::uint8_t>(s);
    }
  }
  if (state_ != RuntimeState::fault && cycle_ - last_valid_cycle_ > std::uint32_t(kStaleInputCycles)) {
    statistics_.stale_events += 1;
    enter(RuntimeState::fault);
  }
}

void Runtime::handle_target_commit(const hal::CanFrame& frame) {
  statistics_.targets_received += 1;
  const bool well_formed = frame.dlc == 6 && pending_xy_;
  const auto mode = static_cast<protocol::TargetMode>(protocol::get_raw(frame, protocol::signal::target_z[1]));
  const auto sequence = static_cast<std::uint8_t>(protocol::get_raw(frame, protocol::signal::target_z[2]));
  last_ik_report_ = IkReport{};
  last_ik_report_.sequence = sequence;

  Pose target;
  target.position_mm = model::Vec3<Scalar>(Scalar(pending_x_mm_), Scalar(pending_y_mm_),
                                           Scalar(protocol::get(frame, protocol::signal::target_z[0])));
  bool valid = well_formed && (mode == protocol::TargetMode::position || mode == protocol::TargetMode::pose);
  if (valid && mode == protocol::TargetMode::pose) {
    const double* q = pending_quaternion_;
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    valid = pending_orientation_ && std::abs(norm - 1.0) <= protocol::kQuaternionNormTolerance;
    if (valid) {
      target.rotation = Eigen::Quaternion<Scalar>(Scalar(q[0] / norm), Scalar(q[1] / norm), Scalar(q[2] / norm),
                                                  Scalar(q[3] / norm))
                            .toRotationMatrix();
    }
  }
  pending_xy_ = false;
  pending_orientation_ = false;

  if (!valid) {
    reject_frame(FaultCode::target_malformed);
    last_ik_report_.outcome = protocol::IkOutcome::rejected_malformed;
  } else if (state_ == RuntimeState::fault || state_ == RuntimeState::boot) {
    last_ik_report_.outcome = protocol::IkOutcome::rejected_state;
  } else {
    solve_target(target, mode, sequence);
  }
  publish_ik_report();
}

void Runtime::solve_target(const Pose& target, protocol::TargetMode mode, std::uint8_t sequence) {
  Joints initial(2 * geometry_.segment_count);
  if (has_setpoints_) {
    initial = setpoint_joints_;
  } else if (has_pose_) {
    initial = latest_pose_.joints;
  } else {
    // A slight bend keeps the first Jacobian away from the straight pose.
    for (int s = 0; s < geometry_.segment_count; ++s) {
      initial[2 * s] = Scalar(0);
      initial[2 * s + 1] = Scalar(0.1);
    }
  }
  model::IkOptions<Scalar> options;
  options.max_iterations = kMaxIkIterations;
  model::IkResult<Scalar, kMaxSegments> result;
  const bool compensated = mode_ == RuntimeState::run;
  if (mode == protocol::TargetMode::pose) {
    result = compensated ? model::solve_ik(target, geometry_, initial, options, correction_)
                         : model::solve_ik(target, geometry_, initial, options);
  } else {
    result = compensated ? model::solve_ik_position(target.position_mm, geometry_, initial, options, correction_)
                         : model::solve_ik_position(target.position_mm, geometry_, initial, options);
  }
  last_ik_report_.sequence = sequence;
  last_ik_report_.model_status = result.status;
  last_ik_report_.iterations = result.iterations;
  last_ik_report_.position_error_mm = result.position_error_mm;

  const bool close_enough =
      result.status == model::Status::ik_not_converged && result.position_error_mm <= kIkAcceptedPositionErrorMm &&
      (mode == protocol::TargetMode::position || result.orientation_error_rad <= kIkAcceptedOrientationErrorRad);
  bool encodable = result.converged() || close_enough;
  for (int i = 0; encodable && i < result.cables_mm.size(); ++i) {
    encodable = result.cables_mm[i] > Scalar(0) && result.cables_mm[i] <= Scalar(protocol::kMaxCableLengthMm);
  }
  if (!encodable) {
    // Setpoints held: the drives keep the last commanded lengths.
    last_ik_report_.outcome = protocol::IkOutcome::unreachable;
    last_event_ = unreported_event_ = FaultCode::target_unreachable;
    last_event_detail_ = static_cast<std::uint8_t>(result.status);
    return;
  }
  last_ik_report_.outcome = protocol::IkOutcome::converged;
  setpoints_mm_ = result.cables_mm;
  setpoint_joints_ = result.joints;
  has_setpoints_ = true;
  publish_setpoints();
}

void Runtime::publish_pose() {
  const Pose& pose = latest_pose_.pose;
  hal::CanFrame frame = protocol::make_frame(protocol::kPosePositionXyId, 8);
  protocol::put(frame, protocol::signal::position_xy[0], pose.position_mm.x());
  protocol::put(frame, protocol::signal::position_xy[1], pose.position_mm.y());
  send(frame);

  frame = protocol::make_frame(protocol::kPosePositionZId, 6);
  protocol::put(frame, protocol::signal::pose_z[0], pose.position_mm.z());
  protocol::put_raw(frame, protocol::signal::pose_z[1], latest_pose_.compensated ? protocol::kPoseFlagCompensated : 0);
  protocol::put_raw(frame, protocol::signal::pose_z[2], cycle_ & 0xFF);
  send(frame);

  double q[4];
  quaternion_of(pose.rotation, q);
  frame = protocol::make_frame(protocol::kPoseOrientationId, 8);
  for (int k = 0; k < 4; ++k) protocol::put(frame, protocol::signal::quaternion[k], q[k]);
  send(frame);
  statistics_.poses_published += 1;
}

void Runtime::publish_setpoints() {
  for (int s = 0; s < geometry_.segment_count; ++s) {
    const double lengths_mm[4] = {setpoints_mm_[4 * s], setpoints_mm_[4 * s + 1], setpoints_mm_[4 * s + 2],
                                  setpoints_mm_[4 * s + 3]};
    hal::CanFrame frame;
    if (protocol::encode_cables(protocol::kCableSetpointBaseId + std::uint32_t(s), lengths_mm, frame)) send(frame);
  }
}

void Runtime::publish_ik_report() {
  hal::CanFrame frame = protocol::make_frame(protocol::kIkReportId, 6);
  const auto& spec = protocol::signal::ik_report;
  protocol::put_raw(frame, spec[0], last_ik_report_.sequence);
  protocol::put_raw(frame, spec[1], static_cast<std::int64_t>(last_ik_report_.outcome));
  protocol::put_raw(frame, spec[2], last_ik_report_.iterations > 255 ? 255 : last_ik_report_.iterations);
  protocol::put_raw(frame, spec[3], static_cast<std::int64_t>(last_ik_report_.model_status));
  const Scalar error_mm = last_ik_report_.position_error_mm;
  protocol::put(frame, spec[4], std::isfinite(error_mm) ? double(error_mm) : protocol::kMaxCableLengthMm + 1.0);
  send(frame);
}

void Runtime::publish_status() {
  hal::CanFrame frame = protocol::make_frame(protocol::kStatusId, 8);
  const auto& status = protocol::signal::status;
  const FaultCode fault = active_fault();
  protocol::put_raw(frame, status[0], static_cast<std::int64_t>(state_));
  protocol::put_raw(frame, status[1], static_cast<std::int64_t>(fault));
  protocol::put_raw(frame, status[2], saturate_u16(statistics_.overruns));
  protocol::put_raw(frame, status[3], saturate_u16(to_us(statistics_.execution_max_ns)));
  protocol::put_raw(frame, status[4], saturate_u16(to_us(statistics_.execution_mean_ns())));
  send(frame);

  frame = protocol::make_frame(protocol::kStatsId, 8);
  const auto& stats = protocol::signal::stats;
  const std::uint8_t detail = fault == boot_fault_ && fault != FaultCode::none ? boot_fault_detail_ : last_event_detail_;
  protocol::put_raw(frame, stats[0], saturate_u16(to_us(statistics_.jitter_max_ns)));
  protocol::put_raw(frame, stats[1], saturate_u16(statistics_.rejected_frames + statistics_.rejected_cable_sets));
  protocol::put_raw(frame, stats[2], statistics_.cycles & 0xFFFF);
  protocol::put_raw(frame, stats[3], detail);
  protocol::put_raw(frame, stats[4], statistics_.stale_events > 255 ? 255 : statistics_.stale_events);
  send(frame);
  unreported_event_ = FaultCode::none;
}

void Runtime::send(const hal::CanFrame& frame) {
  if (hal_.can.send(frame) != hal::CanStatus::ok) last_event_ = unreported_event_ = FaultCode::can_transmit_failed;
}

void Runtime::reject_frame(FaultCode code) {
  statistics_.rejected_frames += 1;
  last_event_ = unreported_event_ = code;
  last_event_detail_ = 0;
}

void Runtime::enter(RuntimeState next) {
  if (next == state_) return;
  state_ = next;
  LogLine line;
  line << "state " << to_string(next);
  hal_.console.write_line(line.c_str());
}

}  // namespace cdcr::firmware
