#pragma once
// A CAN bus for boards without a CAN controller, such as QEMU's MPS2: two
// fixed rings that the runtime and a test driver on the same core exchange
// frames through. Acceptance filters, queue limits and error counters behave
// as a controller's would, so the runtime cannot tell the difference; a
// board with a real controller implements hal::CanBus on its peripheral
// instead (hal/porting.md).

#include <cstddef>
#include <cstdint>

#include <cdcr/hal/can_bus.hpp>
#include <cdcr/hal/can_filter_bank.hpp>
#include <cdcr/hal/can_frame_ring.hpp>

namespace cdcr::cortexm {

template <std::size_t QueueDepth = 32, std::size_t MaxFilters = hal::kMaxCanFilters>
class MailboxCan final : public hal::CanBus {
 public:
  // The runtime's side.
  hal::CanStatus send(const hal::CanFrame& frame) override {
    if (!hal::is_valid(frame)) {
      counters_.tx_dropped += 1;
      return hal::CanStatus::invalid_frame;
    }
    if (!transmitted_.push(frame)) {
      counters_.tx_dropped += 1;
      return hal::CanStatus::queue_full;
    }
    return hal::CanStatus::ok;
  }

  hal::CanStatus receive(hal::CanFrame& frame) override {
    return received_.pop(frame) ? hal::CanStatus::ok : hal::CanStatus::empty;
  }

  bool set_filters(const hal::CanFilter* filters, std::size_t count) override {
    return filters_.assign(filters, count);
  }

  hal::CanErrorCounters error_counters() const override { return counters_; }

  // The other node's side: a frame from the bus, subject to the filters.
  void deliver(const hal::CanFrame& frame) {
    if (!filters_.accepts(frame.id)) return;
    if (!received_.push(frame)) counters_.rx_overruns += 1;
  }
  // The oldest frame the runtime sent, if any.
  bool take_transmitted(hal::CanFrame& frame) { return transmitted_.pop(frame); }

 private:
  hal::CanFrameRing<QueueDepth> received_;
  hal::CanFrameRing<QueueDepth> transmitted_;
  hal::CanFilterBank<MaxFilters> filters_;
  hal::CanErrorCounters counters_{};
};

}  // namespace cdcr::cortexm
