#pragma once
// A fixed-capacity queue, oldest first: the receive and transmit queues of
// the backends that keep frames in memory (the simulated bus, the QEMU
// boards' mailbox), of CAN frames or of frames with what a queue keeps
// beside them. Storage is inline and nothing allocates; push() refuses an
// item when the ring is full, and the caller counts it.

#include <array>
#include <cstddef>

#include "cdcr/hal/can_bus.hpp"

namespace cdcr::hal {

template <typename Item, std::size_t Capacity>
class FixedRing {
 public:
  static_assert(Capacity > 0, "a ring holds at least one item");

  static constexpr std::size_t capacity() { return Capacity; }
  std::size_t size() const { return count_; }
  bool empty() const { return count_ == 0; }

  // False, and the item dropped, when the ring is full.
  bool push(const Item& item) {
    if (count_ == Capacity) return false;
    items_[(head_ + count_) % Capacity] = item;
    ++count_;
    return true;
  }

  // The oldest item, left in the ring; the ring must not be empty.
  const Item& front() const { return items_[head_]; }

  // The oldest item; false when the ring is empty.
  bool pop(Item& item) {
    if (count_ == 0) return false;
    item = items_[head_];
    head_ = (head_ + 1) % Capacity;
    --count_;
    return true;
  }

 private:
  std::array<Item, Capacity> items_{};
  std::size_t head_ = 0;
  std::size_t count_ = 0;
};

template <std::size_t Capacity>
using CanFrameRing = FixedRing<CanFrame, Capacity>;

}  // namespace cdcr::hal
