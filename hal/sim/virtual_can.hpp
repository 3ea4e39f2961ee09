#pragma once
// An in-process CAN bus: every node's send() is delivered to every other
// node's receive queue that accepts it, in order, with no arbitration delay.
// Queues are fixed rings, so the simulated bus never allocates either.

#include <array>
#include <cstddef>

#include <cdcr/firmware/capacity.hpp>
#include <cdcr/hal/can_bus.hpp>

namespace cdcr::sim {

class VirtualCanBus;

class VirtualCanNode final : public hal::CanBus {
 public:
  hal::CanStatus send(const hal::CanFrame& frame) override;
  hal::CanStatus receive(hal::CanFrame& frame) override;
  bool set_filters(const hal::CanFilter* filters, std::size_t count) override;
  hal::CanErrorCounters error_counters() const override { return counters_; }

  std::size_t pending() const { return count_; }
  // Simulates a node dropping off the bus: its sends fail with bus_off.
  void set_bus_off(bool bus_off) { bus_off_ = bus_off; }

 private:
  friend class VirtualCanBus;
  bool accepts(std::uint32_t id) const;
  void deliver(const hal::CanFrame& frame);

  VirtualCanBus* bus_ = nullptr;
  std::array<hal::CanFrame, firmware::kRxQueueDepth> queue_{};
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  std::array<hal::CanFilter, firmware::kMaxCanFilters> filters_{};
  std::size_t filter_count_ = 0;
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
