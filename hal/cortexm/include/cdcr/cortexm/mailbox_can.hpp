#pragma once
// A CAN bus for boards without a CAN controller, such as QEMU's MPS2: two
// fixed rings that the runtime and a test driver on the same core exchange
// frames through. Acceptance filters, queue limits and error counters behave
// as a controller's would, so the runtime cannot tell the difference; a
// board with a real controller implements hal::CanBus on its peripheral
// instead (see the README).

#include <array>
#include <cstddef>
#include <cstdint>

#include <cdcr/hal/can_bus.hpp>

namespace cdcr::cortexm {

template <std::size_t QueueDepth = 32, std::size_t MaxFilters = 4>
class MailboxCan final : public hal::CanBus {
 public:
  // The runtime's side.
  hal::CanStatus send(const hal::CanFrame& frame) override {
    if (frame.id > 0x7FF || frame.dlc > 8) {
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
    if (count > MaxFilters) return false;
    for (std::size_t i = 0; i < count; ++i) filters_[i] = filters[i];
    filter_count_ = count;
    return true;
  }

  hal::CanErrorCounters error_counters() const override { return counters_; }

  // The other node's side: a frame from the bus, subject to the filters.
  void deliver(const hal::CanFrame& frame) {
    if (!accepts(frame.id)) return;
    if (!received_.push(frame)) counters_.rx_overruns += 1;
  }
  // The oldest frame the runtime sent, if any.
  bool take_transmitted(hal::CanFrame& frame) { return transmitted_.pop(frame); }

 private:
  class Ring {
   public:
    bool push(const hal::CanFrame& frame) {
      if (count_ == QueueDepth) return false;
      frames_[(head_ + count_) % QueueDepth] = frame;
      ++count_;
      return true;
    }
    bool pop(hal::CanFrame& frame) {
      if (count_ == 0) return false;
      frame = frames_[head_];
      head_ = (head_ + 1) % QueueDepth;
      --count_;
      return true;
    }

   private:
    std::array<hal::CanFrame, QueueDepth> frames_{};
    std::size_t head_ = 0;
    std::size_t count_ = 0;
  };

  bool accepts(std::uint32_t id) const {
    if (filter_count_ == 0) return true;
    for (std::size_t i = 0; i < filter_count_; ++i) {
      if ((id & filters_[i].mask) == (filters_[i].id & filters_[i].mask)) return true;
    }
    return false;
  }

  Ring received_;
  Ring transmitted_;
  std::array<hal::CanFilter, MaxFilters> filters_{};
  std::size_t filter_count_ = 0;
  hal::CanErrorCounters counters_{};
};

}  // namespace cdcr::cortexm
