#pragma once
// A CanBus that sends every frame in one format: on a bus configured for
// CAN FD, a frame of up to 8 bytes goes out as an FD frame of that length,
// with the bit-rate switch when the format has it. A node of a CAN FD bus
// may send classical frames too, but then each of its frames costs the
// classical arbitration and CRC at the nominal rate; one format per bus is
// what the bus budget (firmware/protocol/bus_budget.hpp) counts.
//
// An FD format is refused on a controller that is not fd_capable(); a bus
// in the classical format passes frames as they are (an FD frame is then
// refused by the controller beneath).

#include <cstddef>

#include "cdcr/hal/can_bus.hpp"
#include "cdcr/hal/can_timing.hpp"

namespace cdcr::hal {

class FormattedCanBus final : public CanBus {
 public:
  explicit FormattedCanBus(CanBus& bus) : bus_(bus) {}

  // False, and the format unchanged, for an FD format on a classical controller.
  bool set_format(CanFormat format) {
    if (format != CanFormat::classical && !bus_.fd_capable()) return false;
    format_ = format;
    return true;
  }
  CanFormat format() const { return format_; }
  bool fd() const { return format_ != CanFormat::classical; }

  CanStatus send(const CanFrame& frame) override {
    if (format_ == CanFormat::classical) return bus_.send(frame);
    CanFrame formatted = frame;
    formatted.flags = kCanFdFrame | (format_ == CanFormat::fd_bit_rate_switch ? kCanBitRateSwitch : 0);
    return bus_.send(formatted);
  }
  CanStatus receive(CanFrame& frame) override { return bus_.receive(frame); }
  bool set_filters(const CanFilter* filters, std::size_t count) override { return bus_.set_filters(filters, count); }
  CanErrorCounters error_counters() const override { return bus_.error_counters(); }
  bool fd_capable() const override { return bus_.fd_capable(); }

 private:
  CanBus& bus_;
  CanFormat format_ = CanFormat::classical;
};

}  // namespace cdcr::hal
