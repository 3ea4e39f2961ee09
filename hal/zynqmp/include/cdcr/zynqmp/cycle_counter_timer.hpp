#pragma once
// The runtime's clock and periodic timer on the Cortex-R5's performance
// monitor cycle counter (PMCCNTR), polled: the R5F gets no timer interrupt
// under QEMU 7.2 (no interrupt controller is wired to the RPU), and the
// counter needs none. The 32-bit counter is extended to 64 bits on every
// read, which the 1 kHz cycle does far more often than once per wrap (4.3 s
// at 1 GHz).
//
// QEMU counts PMCCNTR at 1 GHz of its virtual clock, whatever the core's
// clock; with -icount shift=0 one instruction is 1 ns, so the counter counts
// instructions. On silicon it counts the R5's core clock (up to 600 MHz on
// the ZynqMP).

#include <cstdint>

#include <cdcr/hal/clock.hpp>
#include <cdcr/hal/release_schedule.hpp>

namespace cdcr::zynqmp {

// PMCCNTR's rate under QEMU.
inline constexpr std::uint32_t kQemuCycleCounterHz = 1'000'000'000u;

class CycleCounterTimer final : public hal::MonotonicClock, public hal::PeriodicTimer {
 public:
  // `counter_hz` must divide 1 GHz (whole nanoseconds per count).
  explicit constexpr CycleCounterTimer(std::uint32_t counter_hz)
      : ns_per_count_(counter_hz != 0 && 1000000000u % counter_hz == 0 ? 1000000000u / counter_hz : 1) {}

  // Resets and enables the counter (done once; start() and now_ns() call it).
  void enable();

  void start(std::int64_t period_ns) override;
  // Spins on the counter to the next release; a release already past is
  // missed, not served late.
  hal::TimerTick wait_next() override;
  std::int64_t period_ns() const override { return schedule_.period(); }
  std::uint32_t overruns() const override { return schedule_.missed_total(); }

  std::int64_t now_ns() const override { return static_cast<std::int64_t>(now_counts() * ns_per_count_); }
  // Counts since enable(), 64 bits.
  std::uint64_t now_counts() const;

 private:
  std::uint32_t ns_per_count_;
  bool enabled_ = false;
  mutable std::uint32_t last_low_ = 0;
  mutable std::uint64_t high_ = 0;  // the wraps seen, times 2^32
  hal::ReleaseSchedule schedule_;   // in nanoseconds
};

}  // namespace cdcr::zynqmp
