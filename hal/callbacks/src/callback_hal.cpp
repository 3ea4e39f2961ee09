#include "cdcr/callbacks/callback_hal.hpp"

namespace cdcr::callbacks {

std::int64_t CallbackClock::now_ns() const {
  return callbacks_.now_ns != nullptr ? callbacks_.now_ns(callbacks_.user) : 0;
}

void SteppedTimer::start(std::int64_t period_ns) {
  period_ns_ = period_ns > 0 ? period_ns : 0;
  started_ = false;
  schedule_.start(0, period_ns_);
}

hal::TimerTick SteppedTimer::wait_next() {
  hal::TimerTick tick;
  const std::int64_t now = clock_.now_ns();
  if (period_ns_ == 0) {
    tick.release_ns = now;
    return tick;
  }
  if (!started_) {
    started_ = true;
    schedule_.start(now, period_ns_);
  }
  tick.missed_releases = schedule_.skip_to_latest(now);
  tick.release_ns = schedule_.take();
  return tick;
}

namespace {

cdcr_can_frame to_board(const hal::CanFrame& frame) {
  cdcr_can_frame out{};
  out.id = frame.id;
  out.dlc = frame.dlc;
  for (int i = 0; i < 8; ++i) out.data[i] = frame.data[i];
  return out;
}

// A DLC beyond 8 from the board is cut to 8.
void from_board(const cdcr_can_frame& in, hal::CanFrame& frame) {
  frame.id = in.id;
  frame.dlc = in.dlc <= 8 ? in.dlc : 8;
  for (int i = 0; i < 8; ++i) frame.data[i] = in.data[i];
}

}  // namespace

hal::CanStatus CallbackBus::send(const hal::CanFrame& frame) {
  if (callbacks_.can_send == nullptr) return hal::CanStatus::ok;
  const cdcr_can_frame out = to_board(frame);
  if (callbacks_.can_send(callbacks_.user, &out) == 0) return hal::CanStatus::ok;
  ++counters_.tx_dropped;
  return hal::CanStatus::queue_full;
}

hal::CanStatus CallbackBus::receive(hal::CanFrame& frame) {
  cdcr_can_frame in{};
  if (callbacks_.can_receive == nullptr || callbacks_.can_receive(callbacks_.user, &in) != 1) {
    return hal::CanStatus::empty;
  }
  from_board(in, frame);
  return hal::CanStatus::ok;
}

bool CallbackBus::set_filters(const hal::CanFilter* filters, std::size_t count) {
  if (callbacks_.can_receive == nullptr) return true;
  if (callbacks_.can_set_filters == nullptr || count > std::size_t(hal::kMaxCanFilters)) return false;
  cdcr_can_filter out[hal::kMaxCanFilters] = {};
  for (std::size_t i = 0; i < count; ++i) out[i] = cdcr_can_filter{filters[i].id, filters[i].mask};
  return callbacks_.can_set_filters(callbacks_.user, out, count) == 1;
}

hal::CanStatus CallbackDrivesBus::send(const hal::CanFrame& frame) {
  if (callbacks_.drives_can_send == nullptr) return hal::CanStatus::ok;
  const cdcr_can_frame out = to_board(frame);
  if (callbacks_.drives_can_send(callbacks_.user, bus_, &out) == 0) return hal::CanStatus::ok;
  ++counters_.tx_dropped;
  return hal::CanStatus::queue_full;
}

hal::CanStatus CallbackDrivesBus::receive(hal::CanFrame& frame) {
  cdcr_can_frame in{};
  if (callbacks_.drives_can_receive == nullptr || callbacks_.drives_can_receive(callbacks_.user, bus_, &in) != 1) {
    return hal::CanStatus::empty;
  }
  from_board(in, frame);
  return hal::CanStatus::ok;
}

void CallbackConsole::write_line(const char* line) {
  if (callbacks_.console_write_line != nullptr) callbacks_.console_write_line(callbacks_.user, line);
}

}  // namespace cdcr::callbacks
