#pragma once
// An in-process CAN bus: every node's send() is delivered to every other
// node's receive queue that accepts it, in order, with no arbitration delay.
// Queues are fixed rings, so the simulated bus never allocates either.

#include <array>
#include <cstddef>

#include <cdcr/hal/can_bus.hpp>
#include <cdcr/hal/can_filter_bank.hpp>
#include <cdcr/hal/can_frame_ring.hpp>

namespace cdcr::sim {

class VirtualCanBus;

class VirtualCanNode final : public hal::CanBus {
 public:
  // Depth of each node's receive queue (a board's controller FIFO plays
  // this role); beyond it frames are lost and counted as overruns.
  static constexpr std::size_t kRxQueueDepth = 128;

  hal::CanStatus send(const hal::CanFrame& frame) override;
  hal::CanStatus receive(hal::CanFrame& frame) override;
  bool set_filters(const hal::CanFilter* filters, std::size_t count) override {
    return filters_.assign(filters, count);
  }
  hal::CanErrorCounters error_counters() const override { return counters_; }

  std::size_t pending() const { return queue_.size(); }
  // Simulates a node dropping off the bus: its sends fail with bus_off.
  void set_bus_off(bool bus_off) { bus_off_ = bus_off; }

 private:
  friend class VirtualCanBus;
  void deliver(const hal::CanFrame& frame);

  VirtualCanBus* bus_ = nullptr;
  hal::CanFrameRing<kRxQueueDepth> queue_;
  hal::CanFilterBank<> filters_;
  hal::CanErrorCounters counters_{};
  bool bus_off_ = false;
};

class VirtualCanBus {
 public:
  static constexpr int kMaxNodes = 4;

  VirtualCanBus();
  VirtualCanBus(const VirtualCanBus&) = delete;
  VirtualCanBus& operator=(const VirtualCanBus&) = delete;

  VirtualCanNode& node(int index) { return nodes_[static_cast<std::size_t>(index)]; }

 private:
  friend class VirtualCanNode;
  void broadcast(const VirtualCanNode& sender, const hal::CanFrame& frame);

  std::array<VirtualCanNode, kMaxNodes> nodes_;
};

}  // namespace cdcr::sim
