#pragma once
// A fixed-capacity queue of CAN frames, oldest first: the receive and
// transmit queues of the backends that keep frames in memory (the simulated
// bus, the QEMU boards' mailbox). Storage is inline and nothing allocates;
// push() refuses a frame when the ring is full, and the caller counts it.

#include <array>
#include <cstddef>

#include "cdcr/hal/can_bus.hpp"

namespace cdcr::hal {

template <std::size_t Capacity>
class CanFrameRing {
 public:
  static_assert(Capacity > 0, "a ring holds at least one frame");

  static constexpr std::size_t capacity() { return Capacity; }
  std::size_t size() const { return count_; }

  // False, and the frame dropped, when the ring is full.
  bool push(const CanFrame& frame) {
    if (count_ == Capacity) return false;
    frames_[(head_ + count_) % Capacity] = frame;
    ++count_;
    return true;
  }

  // The oldest frame; false when the ring is empty.
  bool pop(CanFrame& frame) {
    if (count_ == 0) return false;
    frame = frames_[head_];
    head_ = (head_ + 1) % Capacity;
    --count_;
    return true;
  }

 private:
  std::array<CanFrame, Capacity> frames_{};
  std::size_t head_ = 0;
  std::size_t count_ = 0;
};

}  // namespace cdcr::hal
