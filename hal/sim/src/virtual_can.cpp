#include "cdcr/sim/virtual_can.hpp"

namespace cdcr::sim {

hal::CanStatus VirtualCanNode::send(const hal::CanFrame& frame) {
  if (bus_off_) {
    counters_.tx_dropped += 1;
    return hal::CanStatus::bus_off;
  }
  if (!hal::is_valid(frame)) {
    counters_.tx_dropped += 1;
    return hal::CanStatus::invalid_frame;
  }
  bus_->broadcast(*this, frame);
  return hal::CanStatus::ok;
}

hal::CanStatus VirtualCanNode::receive(hal::CanFrame& frame) {
  return queue_.pop(frame) ? hal::CanStatus::ok : hal::CanStatus::empty;
}

void VirtualCanNode::deliver(const hal::CanFrame& frame) {
  if (!filters_.accepts(frame.id)) return;
  if (!queue_.push(frame)) counters_.rx_overruns += 1;
}

VirtualCanBus::VirtualCanBus() {
  for (VirtualCanNode& n : nodes_) n.bus_ = this;
}

void VirtualCanBus::broadcast(const VirtualCanNode& sender, const hal::CanFrame& frame) {
  for (VirtualCanNode& n : nodes_) {
    if (&n != &sender) n.deliver(frame);
  }
}

}  // namespace cdcr::sim
