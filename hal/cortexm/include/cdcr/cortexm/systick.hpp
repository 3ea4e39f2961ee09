#pragma once
// The runtime's clock and periodic timer on the Cortex-M SysTick: the 24-bit
// down-counter reloads once per period and its interrupt counts periods, so
// time is periods elapsed plus the counter's progress through the current
// one. Every Cortex-M has SysTick; only the core clock frequency is board
// specific.
//
// Under QEMU with -icount the core clock is virtual and advances a fixed
// amount per instruction, which makes now_ticks() an exact instruction
// counter (see tools/bench/run_qemu_bench.sh).

#include <cstdint>

#include <cdcr/hal/clock.hpp>
#include <cdcr/hal/release_schedule.hpp>

namespace cdcr::cortexm {

class SysTickTimer final : public hal::MonotonicClock, public hal::PeriodicTimer {
 public:
  static constexpr std::uint32_t kMaxReloadTicks = 1u << 24;

  explicit SysTickTimer(std::uint32_t core_clock_hz)
      : core_clock_hz_(core_clock_hz),
        ns_per_tick_(1000000000u % core_clock_hz == 0 ? 1000000000u / core_clock_hz : 0) {}

  // Periods longer than 2^24 core clock ticks are clamped to that.
  void start(std::int64_t period_ns) override;
  hal::TimerTick wait_next() override;
  std::int64_t period_ns() const override { return period_ns_; }
  std::uint32_t overruns() const override { return schedule_.missed_total(); }

  std::int64_t now_ns() const override;
  // Core clock ticks since start().
  std::uint64_t now_ticks() const;
  std::uint32_t core_clock_hz() const { return core_clock_hz_; }

  // Called from the SysTick exception only.
  void on_systick() { periods_ = periods_ + 1; }

 private:
  std::uint32_t core_clock_hz_;
  // Whole nanoseconds per tick where the clock divides 1 GHz (25 MHz: 40),
  // which spares now_ns() a 64-bit division; 0 otherwise.
  std::uint32_t ns_per_tick_;
  std::uint32_t reload_ticks_ = 0;  // ticks per period
  std::int64_t period_ns_ = 0;
  volatile std::uint64_t periods_ = 0;
  hal::ReleaseSchedule schedule_;  // in periods
};

// The timer the SysTick exception reports to; one per core.
void attach_systick(SysTickTimer& timer);

}  // namespace cdcr::cortexm
