#include "sim/virtual_can.hpp"

namespace cdcr::sim {

hal::CanStatus VirtualCanNode::send(const hal::CanFrame& frame) {
  if (bus_off_) {
    counters_.tx_dropped += 1;
    return hal::CanStatus::bus_off;
  }
  if (frame.id > 0x7FF || frame.dlc > 8) {
    counters_.tx_dropped += 1;
    return hal::CanStatus::invalid_frame;
  }
  bus_->broadcast(*this, frame);
  return hal::CanStatus::ok;
}

hal::CanStatus VirtualCanNode::receive(hal::CanFrame& frame) {
  if (count_ == 0) return hal::CanStatus::empty;
  frame = queue_[head_];
  head_ = (head_ + 1) % queue_.size();
  count_ -= 1;
  return hal::CanStatus::ok;
}

bool VirtualCanNode::set_filters(const hal::CanFilter* filters, std::size_t count) {
  if (count > filters_.size()) return false;
  for (std::size_t i = 0; i < count; ++i) filters_[i] = filters[i];
  filter_count_ = count;
  return true;
}

bool VirtualCanNode::accepts(std::uint32_t id) const {
  if (filter_count_ == 0) return true;
  for (std::size_t i = 0; i < filter_count_; ++i) {
    if ((id & filters_[i].mask) == (filters_[i].id & filters_[i].mask)) return true;
  }
  return false;
}

void VirtualCanNode::deliver(const hal::CanFrame& frame) {
  if (!accepts(frame.id)) return;
  if (count_ == queue_.size()) {
    counters_.rx_overruns += 1;
    return;
  }
  queue_[(head_ + count_) % queue_.size()] = frame;
  count_ += 1;
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
