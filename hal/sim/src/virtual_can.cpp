#include "cdcr/sim/virtual_can.hpp"

namespace cdcr::sim {

hal::CanStatus VirtualCanNode::send(const hal::CanFrame& frame) {
  if (bus_off_) {
    counters_.tx_dropped += 1;
    return hal::CanStatus::bus_off;
  }
  if (!hal::is_valid(frame, fd_capable()) ||
      (frame.bit_rate_switch() && bus_->timed() && bus_->rates().data == 0)) {
    counters_.tx_dropped += 1;
    return hal::CanStatus::invalid_frame;
  }
  if (bus_->timed()) return bus_->enqueue(*this, frame);
  bus_->broadcast(*this, frame);
  return hal::CanStatus::ok;
}

bool VirtualCanNode::fd_capable() const { return bus_->fd(); }

hal::CanStatus VirtualCanNode::receive(hal::CanFrame& frame) {
  bus_->catch_up();
  return queue_.pop(frame) ? hal::CanStatus::ok : hal::CanStatus::empty;
}

void VirtualCanNode::deliver(const hal::CanFrame& frame) {
  if (!filters_.accepts(frame.id)) return;
  if (!queue_.push(frame)) counters_.rx_overruns += 1;
}

VirtualCanBus::VirtualCanBus() {
  for (VirtualCanNode& n : nodes_) n.bus_ = this;
}

void VirtualCanBus::set_timing(const hal::MonotonicClock& clock, const hal::CanBitRates& rates) {
  clock_ = &clock;
  rates_ = rates;
  idle_from_ns_ = clock.now_ns();
}

void VirtualCanBus::broadcast(const VirtualCanNode& sender, const hal::CanFrame& frame) {
  for (VirtualCanNode& n : nodes_) {
    if (&n != &sender) n.deliver(frame);
  }
}

hal::CanStatus VirtualCanBus::enqueue(VirtualCanNode& sender, const hal::CanFrame& frame) {
  catch_up();
  if (!sender.tx_.push({frame, clock_->now_ns()})) {
    sender.counters_.tx_dropped += 1;
    return hal::CanStatus::queue_full;
  }
  return hal::CanStatus::ok;
}

int VirtualCanBus::next_winner(std::int64_t& start_ns) const {
  // The bus is free from idle_from_ns_; the first frame queued after that
  // starts when it is queued. Every head queued by the start competes.
  bool any = false;
  std::int64_t earliest = 0;
  for (const VirtualCanNode& n : nodes_) {
    if (n.tx_.empty()) continue;
    if (!any || n.tx_.front().queued_ns < earliest) earliest = n.tx_.front().queued_ns;
    any = true;
  }
  if (!any) return -1;
  start_ns = earliest > idle_from_ns_ ? earliest : idle_from_ns_;
  int winner = -1;
  for (int i = 0; i < kMaxNodes; ++i) {
    const VirtualCanNode& n = nodes_[static_cast<std::size_t>(i)];
    if (n.tx_.empty() || n.tx_.front().queued_ns > start_ns) continue;
    if (winner < 0 || n.tx_.front().frame.id < nodes_[static_cast<std::size_t>(winner)].tx_.front().frame.id) winner = i;
  }
  return winner;
}

void VirtualCanBus::catch_up() {
  if (clock_ == nullptr) return;
  const std::int64_t now = clock_->now_ns();
  for (;;) {
    if (in_flight_) {
      if (flight_.end_ns > now) return;
      in_flight_ = false;
      idle_from_ns_ = flight_.end_ns;
      busy_ns_ += flight_.end_ns - flight_.start_ns;
      ++transfers_;
      broadcast(nodes_[static_cast<std::size_t>(flight_.sender)], flight_.frame);
      if (observer_ != nullptr) observer_->on_transfer(flight_);
    }
    std::int64_t start = 0;
    const int winner = next_winner(start);
    // A node may still send at now: arbitration at now waits for it.
    if (winner < 0 || start >= now) return;
    VirtualCanNode::Queued queued;
    nodes_[static_cast<std::size_t>(winner)].tx_.pop(queued);
    flight_.frame = queued.frame;
    flight_.sender = winner;
    flight_.queued_ns = queued.queued_ns;
    flight_.start_ns = start;
    flight_.bits = hal::can_frame_bits(flight_.frame);
    flight_.end_ns = start + hal::can_frame_time_ns(flight_.bits, rates_);
    in_flight_ = true;
  }
}

}  // namespace cdcr::sim
