#pragma once
// What the runtime's parts send, and the events they record on the way: a
// frame the bus refuses is an event of its own (can_transmit_failed). The
// event not yet reported is what the next STATUS carries (Runtime::active_fault).

#include "cdcr/firmware/fault.hpp"
#include "cdcr/firmware/fault_detail.hpp"
#include "cdcr/hal/can_bus.hpp"

namespace cdcr::firmware {

class Outbox {
 public:
  explicit Outbox(hal::CanBus& bus) : bus_(bus) {}

  void send(const hal::CanFrame& frame) {
    if (bus_.send(frame) != hal::CanStatus::ok) record_event(FaultCode::can_transmit_failed);
  }

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
  hal::CanBus& bus_;
  FaultCode last_event_ = FaultCode::none;
  FaultCode unreported_event_ = FaultCode::none;
  FaultDetail last_event_detail_;
};

}  // namespace cdcr::firmware
