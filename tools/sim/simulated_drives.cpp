#include "sim/simulated_drives.hpp"

#include <algorithm>

#include <cdcr/firmware/protocol.hpp>

namespace cdcr::sim {

namespace protocol = firmware::protocol;

SimulatedCableDrives::SimulatedCableDrives(hal::CanBus& bus, const Cables& initial_cables_mm,
                                           double max_rate_mm_per_s)
    : bus_(bus), cables_mm_(initial_cables_mm), setpoints_mm_(initial_cables_mm), max_rate_mm_per_s_(max_rate_mm_per_s) {
  bus_.set_filters(&protocol::kCableSetpointFrames, 1);
}

void SimulatedCableDrives::set_segment_silent(int segment, bool silent) {
  if (segment >= 0 && segment < firmware::kMaxSegments) segment_silent_[segment] = silent;
}

void SimulatedCableDrives::step(double dt_s) {
  const int segments = static_cast<int>(cables_mm_.size() / 4);
  hal::CanFrame frame;
  while (bus_.receive(frame) == hal::CanStatus::ok) {
    if (!protocol::cable_setpoint::kMessage.carries(frame.id)) continue;
    protocol::CableSetpoint setpoint;
    if (protocol::decode(frame, setpoint) != protocol::DecodeStatus::ok || setpoint.segment >= segments) {
      rejected_frames_ += 1;
      continue;
    }
    for (int k = 0; k < 4; ++k) setpoints_mm_[4 * setpoint.segment + k] = setpoint.lengths_mm[k];
    setpoint_frames_ += 1;
  }
  const double max_step_mm = max_rate_mm_per_s_ * dt_s;
  for (Eigen::Index i = 0; i < cables_mm_.size(); ++i) {
    cables_mm_[i] += std::clamp(setpoints_mm_[i] - cables_mm_[i], -max_step_mm, max_step_mm);
  }
  if (silent_) return;
  for (int s = 0; s < segments; ++s) {
    if (segment_silent_[s]) continue;
    const protocol::CableFeedback feedback{
        s, {cables_mm_[4 * s], cables_mm_[4 * s + 1], cables_mm_[4 * s + 2], cables_mm_[4 * s + 3]}};
    if (protocol::encode(feedback, frame)) bus_.send(frame);
  }
}

}  // namespace cdcr::sim
