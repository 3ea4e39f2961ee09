#include "sim/simulated_drives.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <cdcr/firmware/protocol.hpp>

namespace cdcr::sim {

namespace protocol = firmware::protocol;

SimulatedCableDrives::SimulatedCableDrives(hal::CanBus& bus, const Cables& initial_cables_mm,
                                           double max_rate_mm_per_s, std::vector<int> segment_cables)
    : bus_(bus),
      cables_mm_(initial_cables_mm),
      setpoints_mm_(initial_cables_mm),
      max_rate_mm_per_s_(max_rate_mm_per_s),
      segment_cables_(std::move(segment_cables)) {
  if (segment_cables_.empty()) segment_cables_.assign(static_cast<std::size_t>(cables_mm_.size() / 4), 4);
  int first = 0;
  for (const int count : segment_cables_) {
    first_cable_.push_back(first);
    first += count;
  }
  if (first != cables_mm_.size()) throw std::invalid_argument("the drives' cables and the segments' counts disagree");
  static constexpr hal::CanFilter kSetpointFrames[] = {protocol::kCableSetpointFrames,
                                                       protocol::kCableSetpointsFdFrames};
  bus_.set_filters(kSetpointFrames, 2);
}

void SimulatedCableDrives::set_segment_silent(int segment, bool silent) {
  if (segment >= 0 && segment < firmware::kMaxSegments) segment_silent_[segment] = silent;
}

// A segment's setpoint, or false for a segment the robot lacks or a
// four-cable segment's setpoint without its fourth length.
bool SimulatedCableDrives::take(const protocol::CableSetpoint& setpoint) {
  const int segments = static_cast<int>(segment_cables_.size());
  if (setpoint.segment >= segments ||
      (segment_cables_[static_cast<std::size_t>(setpoint.segment)] == 4 && std::isnan(setpoint.lengths_mm[3]))) {
    return false;
  }
  const auto segment = static_cast<std::size_t>(setpoint.segment);
  for (int k = 0; k < segment_cables_[segment]; ++k) setpoints_mm_[first_cable_[segment] + k] = setpoint.lengths_mm[k];
  setpoint_frames_ += 1;
  return true;
}

void SimulatedCableDrives::step(double dt_s) {
  const int segments = static_cast<int>(segment_cables_.size());
  hal::CanFrame frame;
  while (bus_.receive(frame) == hal::CanStatus::ok) {
    if (protocol::cable_setpoint::kMessage.carries(frame.id)) {
      protocol::CableSetpoint setpoint;
      if (protocol::decode(frame, setpoint) != protocol::DecodeStatus::ok || !take(setpoint)) rejected_frames_ += 1;
    } else if (protocol::cable_setpoints_fd::kMessage.carries(frame.id)) {
      protocol::CableSetpointsFd setpoints;
      bool taken = protocol::decode(frame, setpoints) == protocol::DecodeStatus::ok;
      for (int k = 0; taken && k < setpoints.segment_count; ++k) taken = take(setpoints.segments[k]);
      if (!taken) rejected_frames_ += 1;
    }
  }
  const double max_step_mm = max_rate_mm_per_s_ * dt_s;
  for (Eigen::Index i = 0; i < cables_mm_.size(); ++i) {
    cables_mm_[i] += std::clamp(setpoints_mm_[i] - cables_mm_[i], -max_step_mm, max_step_mm);
  }
  if (silent_) return;
  for (int s = 0; s < segments; ++s) {
    if (segment_silent_[s]) continue;
    const auto segment = static_cast<std::size_t>(s);
    const auto feedback = protocol::segment_cables_frame<protocol::CableFeedback>(
        s, cables_mm_, first_cable_[segment], segment_cables_[segment]);
    if (protocol::encode(feedback, frame)) bus_.send(frame);
  }
}

}  // namespace cdcr::sim
