#pragma once
// The cable drives as the runtime sees them over CAN: they take setpoint
// frames (CABLE_SETPOINT, or CABLE_SETPOINTS_FD on an FD bus), move each cable toward its setpoint at a limited rate, and report
// the achieved lengths every step, one feedback frame per segment.

#include <vector>

#include <cdcr/firmware/capacity.hpp>
#include <cdcr/firmware/protocol/frames.hpp>
#include <cdcr/hal/can_bus.hpp>
#include <cdcr/model/geometry.hpp>
#include <cdcr/model/types.hpp>

namespace cdcr::sim {

// Each segment's cable count, as the drives take it.
template <typename S, int Max>
std::vector<int> cables_per_segment(const model::RobotGeometry<S, Max>& geometry) {
  std::vector<int> counts;
  for (int i = 0; i < geometry.segment_count; ++i) counts.push_back(geometry.segments[i].cables.count);
  return counts;
}

class SimulatedCableDrives {
 public:
  using Cables = model::CableVector<double, firmware::kMaxSegments>;

  // `bus` is the drives' own node; lengths start at initial_cables_mm, the
  // cables of each segment in turn (segment_cables: how many each has;
  // empty: four each).
  SimulatedCableDrives(hal::CanBus& bus, const Cables& initial_cables_mm, double max_rate_mm_per_s,
                       std::vector<int> segment_cables = {});

  // Takes every pending setpoint frame, moves the cables by dt_s, publishes.
  void step(double dt_s);

  // Stops or resumes the feedback frames (a drive losing its bus): of every
  // segment, or of one segment's drive only.
  void set_silent(bool silent) { silent_ = silent; }
  void set_segment_silent(int segment, bool silent);

  const Cables& cables_mm() const { return cables_mm_; }
  const Cables& setpoints_mm() const { return setpoints_mm_; }
  // Segment setpoints taken: one a CABLE_SETPOINT frame, up to four a CABLE_SETPOINTS_FD.
  std::uint32_t setpoint_frames() const { return setpoint_frames_; }
  std::uint32_t rejected_frames() const { return rejected_frames_; }

 private:
  bool take(const firmware::protocol::CableSetpoint& setpoint);

  hal::CanBus& bus_;
  Cables cables_mm_;
  Cables setpoints_mm_;
  double max_rate_mm_per_s_;
  std::vector<int> segment_cables_;
  std::vector<int> first_cable_;
  bool silent_ = false;
  bool segment_silent_[firmware::kMaxSegments] = {};
  std::uint32_t setpoint_frames_ = 0;
  std::uint32_t rejected_frames_ = 0;
};

}  // namespace cdcr::sim
