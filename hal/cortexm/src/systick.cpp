#include "cdcr/cortexm/systick.hpp"

namespace cdcr::cortexm {
namespace {

struct SysTickRegisters {
  volatile std::uint32_t control;  // CSR
  volatile std::uint32_t reload;   // RVR
  volatile std::uint32_t current;  // CVR
  volatile std::uint32_t calibration;
};
SysTickRegisters& systick() { return *reinterpret_cast<SysTickRegisters*>(0xE000E010u); }

constexpr std::uint32_t kEnable = 1u << 0;
constexpr std::uint32_t kInterrupt = 1u << 1;
constexpr std::uint32_t kCoreClock = 1u << 2;

SysTickTimer* attached = nullptr;

}  // namespace

void attach_systick(SysTickTimer& timer) { attached = &timer; }

void SysTickTimer::start(std::int64_t period_ns) {
  std::uint64_t ticks = static_cast<std::uint64_t>(period_ns) * core_clock_hz_ / 1000000000u;
  if (ticks < 2) ticks = 2;
  if (ticks > kMaxReloadTicks) ticks = kMaxReloadTicks;
  reload_ticks_ = static_cast<std::uint32_t>(ticks);
  period_ns_ = static_cast<std::int64_t>(ticks * 1000000000u / core_clock_hz_);

  SysTickRegisters& registers = systick();
  registers.control = 0;
  periods_ = 0;
  schedule_.start(1, 1);  // in periods: release k is the k-th reload
  registers.reload = reload_ticks_ - 1;
  registers.current = 0;  // any write clears the counter, so the first period is whole
  registers.control = kEnable | kInterrupt | kCoreClock;
}

std::uint64_t SysTickTimer::now_ticks() const {
  if (reload_ticks_ == 0) return 0;  // not started: time stands at 0
  // The exception may land between the two reads; a period count that moved
  // means the counter reloaded in between, so read again.
  for (;;) {
    const std::uint64_t periods = periods_;
    const std::uint32_t remaining = systick().current;
    if (periods == periods_) return periods * reload_ticks_ + (reload_ticks_ - 1 - remaining);
  }
}

std::int64_t SysTickTimer::now_ns() const {
  const std::uint64_t ticks = now_ticks();
  if (ns_per_tick_ != 0) return static_cast<std::int64_t>(ticks * ns_per_tick_);
  // Split so that the product stays within 64 bits for centuries of uptime.
  const std::uint64_t seconds = ticks / core_clock_hz_;
  const std::uint64_t rest = ticks % core_clock_hz_;
  return static_cast<std::int64_t>(seconds * 1000000000u + rest * 1000000000u / core_clock_hz_);
}

hal::TimerTick SysTickTimer::wait_next() {
  hal::TimerTick tick;
  // Sleeping until an interrupt is the wait; one that woke the core late
  // serves the latest reload, and the ones before it are missed.
  while (periods_ < std::uint64_t(schedule_.next_release())) asm volatile("wfi" ::: "memory");
  tick.missed_releases = schedule_.skip_to_latest(static_cast<std::int64_t>(periods_));
  tick.release_ns = schedule_.take() * period_ns_;
  return tick;
}

}  // namespace cdcr::cortexm

extern "C" void cdcr_cortexm_systick_handler() {
  if (cdcr::cortexm::attached != nullptr) cdcr::cortexm::attached->on_systick();
}
