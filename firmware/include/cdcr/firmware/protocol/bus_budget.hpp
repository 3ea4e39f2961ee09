#pragma once
// The CAN bus budget of a configuration, computed before anything runs: for
// every message of the protocol, the frames a second the runtime and its
// peers put on the bus at a cycle rate, and each frame's worst-case time on
// the wire (hal/can_timing.hpp: worst-case stuffing, the interframe space);
// their sum over a second is the bus's worst-case load. A configuration whose
// worst case is above kMaxBusLoad is refused (cdcr-runtime, cdcr bus).
//
// The frames a cycle, as the runtime sends and takes them (runtime.cpp):
//   CABLE_FEEDBACK   one per segment, every cycle (from the drives);
//   CABLE_SETPOINT   one per segment per solved target: every cycle while
//                    a target is streamed every cycle;
//   TARGET_*         a streamed pose target: ORIENTATION, POSITION_XY and
//                    POSITION_Z, every cycle;
//   IK_REPORT        one per target (every target ends once: converged,
//                    superseded, ...) and one every kIkProgressEveryCycles
//                    while a request runs;
//   POSE_*           three frames every pose_every cycles;
//   POSE_UNCERTAINTY one every uncertainty_every cycles: a variance begins
//                    at most that often and ends at least a cycle on (the
//                    model's own evaluation may take longer: fewer frames);
//   STATUS, STATS    one each every status_every cycles (publish_rates.hpp).
// On a CAN FD bus (every node sending in the bus's format, formatted_can_bus.hpp)
// the pose and its radii go as one POSE_FD every pose_every cycles, a
// streamed target as one TARGET_FD, the setpoints as one CABLE_SETPOINTS_FD
// per four segments; the other messages as FD frames of their lengths.
// With a bus of their own for the drives (Hal::drives_can) CABLE_FEEDBACK
// and the setpoints are that bus's (BusRole::drives), the rest the host's.
// PAYLOAD, HOMING and a model update's frames are the host's, sent when it
// chooses: the budget leaves them the room between its load and the limit
// (an update's UPDATE_DATA frames should be paced to fit there).

#include <cstdint>

#include "cdcr/firmware/capacity.hpp"
#include "cdcr/firmware/publish_rates.hpp"
#include "cdcr/firmware/protocol/messages.hpp"
#include "cdcr/hal/can_timing.hpp"

namespace cdcr::firmware::protocol {

// What runs on the bus.
struct BusTraffic {
  int segments = 4;
  std::uint32_t cycle_hz = 1000;
  bool streaming = false;  // the host streams a pose target every cycle
  PublishRates rates{};
};

// Which of the traffic a bus carries: all of it, or with two buses the
// host's or the drives'.
enum class BusRole : std::uint8_t { shared, host, drives };

// The bus it runs on.
struct BusSetup {
  hal::CanFormat format = hal::CanFormat::classical;
  hal::CanBitRates rates{};
  BusRole role = BusRole::shared;
  bool fd() const { return format != hal::CanFormat::classical; }
};

// One message's share of the bus.
struct MessageLoad {
  const char* name = nullptr;
  double frames_per_s = 0.0;
  std::uint32_t worst_bits = 0;  // of one frame
  double load = 0.0;             // of the bus's time, worst case (0..)
};

inline constexpr int kBudgetMessages = 12;

struct BusBudget {
  MessageLoad messages[kBudgetMessages];
  int message_count = 0;
  double load = 0.0;             // the bus's worst-case load: the sum of the messages'
  double unstuffed_load = 0.0;   // the same frames without a stuff bit: no content takes less
  double frames_per_s = 0.0;
  bool fits() const { return load <= kMaxBusLoad; }
};

namespace detail {

inline void add_message(BusBudget& budget, const BusSetup& bus, const char* name, std::size_t length,
                        double frames_per_s) {
  if (frames_per_s <= 0.0 || budget.message_count == kBudgetMessages) return;
  const hal::CanFrameBits worst = hal::can_frame_bits_worst_case(length, bus.format);
  const hal::CanFrameBits unstuffed = hal::can_frame_bits_without_stuffing(length, bus.format);
  MessageLoad& line = budget.messages[budget.message_count++];
  line.name = name;
  line.frames_per_s = frames_per_s;
  line.worst_bits = worst.total();
  line.load = frames_per_s * double(hal::can_frame_time_ns(worst, bus.rates)) * 1e-9;
  budget.load += line.load;
  budget.unstuffed_load += frames_per_s * double(hal::can_frame_time_ns(unstuffed, bus.rates)) * 1e-9;
  budget.frames_per_s += frames_per_s;
}
inline void add_message(BusBudget& budget, const BusSetup& bus, const MessageSpec& message, double frames_per_s) {
  add_message(budget, bus, message.name, message.dlc, frames_per_s);
}
inline void add_message(BusBudget& budget, const BusSetup& bus, const FdMessageSpec& message, double frames_per_s) {
  add_message(budget, bus, message.name, message.length, frames_per_s);
}

}  // namespace detail

inline BusBudget bus_budget(const BusTraffic& traffic, const BusSetup& bus) {
  BusBudget budget;
  const double cycles = double(traffic.cycle_hz);
  const double segments = double(traffic.segments);
  const auto every = [cycles](int n) { return n > 0 ? cycles / double(n) : 0.0; };
  const bool drives = bus.role != BusRole::host;
  const bool host = bus.role != BusRole::drives;
  const PublishRates& rates = traffic.rates;
  if (drives) {
    detail::add_message(budget, bus, cable_feedback::kMessage, segments * cycles);
    if (traffic.streaming && bus.fd()) {
      const int frames = (traffic.segments + cable_setpoints_fd::kSegmentsPerFrame - 1) /
                         cable_setpoints_fd::kSegmentsPerFrame;
      detail::add_message(budget, bus, cable_setpoints_fd::kMessage, double(frames) * cycles);
    } else if (traffic.streaming) {
      detail::add_message(budget, bus, cable_setpoint::kMessage, segments * cycles);
    }
  }
  if (!host) return budget;
  if (traffic.streaming) {
    if (bus.fd()) {
      detail::add_message(budget, bus, target_fd::kMessage, cycles);
    } else {
      detail::add_message(budget, bus, target_orientation::kMessage, cycles);
      detail::add_message(budget, bus, target_position_xy::kMessage, cycles);
      detail::add_message(budget, bus, target_position_z::kMessage, cycles);
    }
    detail::add_message(budget, bus, ik_report::kMessage, cycles + every(kIkProgressEveryCycles));
  }
  if (bus.fd()) {
    detail::add_message(budget, bus, pose_fd::kMessage, every(rates.pose_every));
  } else {
    detail::add_message(budget, bus, pose_position_xy::kMessage, every(rates.pose_every));
    detail::add_message(budget, bus, pose_position_z::kMessage, every(rates.pose_every));
    detail::add_message(budget, bus, pose_orientation::kMessage, every(rates.pose_every));
    detail::add_message(budget, bus, pose_uncertainty::kMessage, every(rates.uncertainty_every));
  }
  detail::add_message(budget, bus, status::kMessage, every(rates.status_every));
  detail::add_message(budget, bus, stats::kMessage, every(rates.status_every));
  return budget;
}

}  // namespace cdcr::firmware::protocol
