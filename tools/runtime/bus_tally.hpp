#pragma once
// What a timed simulated bus carried in a cdcr-runtime --sim run: the bus's
// measured load, and per message the frames, their latency (from send() to
// the frame's last bit) and those that arrived too late for their cycle: a
// frame sent in a cycle's period must be delivered before the next release.

#include <cstdint>
#include <string>
#include <vector>

#include <cdcr/firmware/protocol/message_codec.hpp>
#include <cdcr/sim/virtual_can.hpp>

namespace cdcr::runtime_host {

class BusTally final : public sim::CanTransferObserver {
 public:
  // The cycle releases: first_release_ns + k x period_ns, k = 0, 1, ...;
  // a frame sent before the first release is due by it.
  void set_releases(std::int64_t first_release_ns, std::int64_t period_ns) {
    first_release_ns_ = first_release_ns;
    period_ns_ = period_ns;
  }
  // Frames on the bus at the protocol's identifiers moved by this much.
  void set_id_offset(std::uint32_t offset) { id_offset_ = offset; }
  void on_transfer(const sim::CanTransfer& transfer) override;

  long frames() const { return frames_; }
  // The lowest and highest identifier seen on the wire.
  std::uint32_t lowest_id() const { return lowest_id_; }
  std::uint32_t highest_id() const { return highest_id_; }
  long late() const { return late_; }
  // The bus's share of time carrying frames, over [0, now_ns].
  static double measured_load(const sim::VirtualCanBus& bus, std::int64_t now_ns) {
    return now_ns > 0 ? double(bus.busy_ns()) / double(now_ns) : 0.0;
  }
  // One line a message: frames, latency p50/p99/max (us), late.
  std::string table() const;

 private:
  struct Kind {
    const char* name = nullptr;  // null: not the protocol's
    std::uint32_t id = 0x800;    // the message's first, for the table's order
    std::vector<double> latency_us;
    long late = 0;
  };
  std::int64_t deadline_ns(std::int64_t queued_ns) const;

  std::vector<Kind> kinds_;
  std::uint32_t id_offset_ = 0;
  std::int64_t first_release_ns_ = -1;
  std::int64_t period_ns_ = 0;
  long frames_ = 0;
  long late_ = 0;
  std::uint32_t lowest_id_ = 0x7FF;
  std::uint32_t highest_id_ = 0;
};

struct BusChoice;

// A timed bus of the run and what it carried.
struct TimedBus {
  const sim::VirtualCanBus* bus = nullptr;
  const BusTally* tally = nullptr;
};

// Each of the run's buses (the host's first, as cli::bus_budgets_of): the
// measured load against the budget's worst case and the load without
// stuffing (a check: measured within them), the frames and those late,
// then the tally's table.
std::string timed_bus_report(const std::vector<TimedBus>& buses, std::int64_t now_ns, int segments, double rate_hz,
                             bool streaming, const BusChoice& choice);

}  // namespace cdcr::runtime_host
