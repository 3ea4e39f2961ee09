#pragma once
// What the runtime's parts send, and the events they record on the way: a
// frame the bus refuses is an event of its own (can_transmit_failed). The
// event not yet reported is what the next STATUS carries (Runtime::active_fault).
//
// Two buses: the host's (poses, reports, STATUS) and the drives' (the
// setpoints); with one bus they are the same. Each sends in its format
// (formatted_can_bus.hpp); an FD bus carries the FD messages (messages.hpp).

#include "cdcr/firmware/fault.hpp"
#include "cdcr/firmware/fault_detail.hpp"
#include "cdcr/hal/can_bus.hpp"
#include "cdcr/hal/formatted_can_bus.hpp"

namespace cdcr::firmware {

class Outbox {
 public:
  Outbox(hal::FormattedCanBus& host, hal::FormattedCanBus& drives) : host_(host), drives_(drives) {}

  void send(const hal::CanFrame& frame) { send_on(host_, frame); }
  void send_to_drives(const hal::CanFrame& frame) { send_on(drives_, frame); }
  bool drives_fd() const { return drives_.fd(); }

  void record_event(FaultCode code, FaultDetail detail = FaultDetail()) {
    last_event_ = unreported_event_ = code;
    last_event_detail_ = detail;
  }

  FaultCode last_event() const { return last_event_; }
  // The latest event since the last STATUS, and its detail.
  FaultCode unreported_event() const { return unreported_event_; }
  FaultDetail last_event_detail() const { return last_event_detail_; }
  void events_reported() { unreported_event_ = FaultCode::none; }

 private:
  void send_on(hal::FormattedCanBus& bus, const hal::CanFrame& frame) {
    if (bus.send(frame) != hal::CanStatus::ok) record_event(FaultCode::can_transmit_failed);
  }

  hal::FormattedCanBus& host_;
  hal::FormattedCanBus& drives_;
  FaultCode last_event_ = FaultCode::none;
  FaultCode unreported_event_ = FaultCode::none;
  FaultDetail last_event_detail_;
};

}  // namespace cdcr::firmware
