#pragma once
// hal::CanBus on the Xilinx CAN controller: the runtime's bus on the R5F
// board. Polled (QEMU 7.2 gives the RPU no interrupts): every receive()
// first moves what the controller's RX FIFO holds into a ring, as far as the
// ring has room, and hands out the oldest frame. With an interrupt, the
// handler calls poll() instead and receive() only pops the ring.

#include <cstddef>
#include <cstdint>

#include <cdcr/hal/can_bus.hpp>
#include <cdcr/hal/can_frame_ring.hpp>

#include "cdcr/zynqmp/xilinx_can_controller.hpp"

namespace cdcr::zynqmp {

template <std::size_t RxQueueDepth = 32>
class XilinxCan final : public hal::CanBus {
 public:
  explicit constexpr XilinxCan(std::uintptr_t base) : controller_(base) {}

  bool start(const CanBitTiming& timing, CanMode mode = CanMode::normal) { return controller_.start(timing, mode); }

  hal::CanStatus send(const hal::CanFrame& frame) override {
    const hal::CanStatus status = controller_.transmit(frame);
    if (status != hal::CanStatus::ok) counters_.tx_dropped += 1;
    return status;
  }

  hal::CanStatus receive(hal::CanFrame& frame) override {
    poll();
    return received_.pop(frame) ? hal::CanStatus::ok : hal::CanStatus::empty;
  }

  // The controller can take four filters (kXilinxCanFilters); more are
  // refused, as are identifiers or masks beyond 11 bits.
  bool set_filters(const hal::CanFilter* filters, std::size_t count) override {
    return controller_.set_filters(filters, count);
  }

  // rx_overruns counts the RX FIFO's overflows (each lost one frame or more:
  // the controller flags, it does not count) and frames the ring had no room
  // for; bus_errors counts the error kinds the controller flagged.
  hal::CanErrorCounters error_counters() const override { return counters_; }

  // The RX FIFO into the ring, and the controller's overflow and error
  // flags into the counters.
  void poll() {
    hal::CanFrame frame;
    while (received_.size() < received_.capacity() && controller_.receive(frame)) received_.push(frame);
    if (controller_.take_rx_overflow()) counters_.rx_overruns += 1;
    counters_.bus_errors += controller_.take_error_flags();
  }

  XilinxCanController& controller() { return controller_; }
  const XilinxCanController& controller() const { return controller_; }

 private:
  XilinxCanController controller_;
  hal::CanFrameRing<RxQueueDepth> received_;
  hal::CanErrorCounters counters_{};
};

}  // namespace cdcr::zynqmp
