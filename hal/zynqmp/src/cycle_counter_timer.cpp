#include "cdcr/zynqmp/cycle_counter_timer.hpp"

#include "cdcr/zynqmp/second_core.hpp"

namespace cdcr::zynqmp {
namespace {

// PMCR: E (enable all counters), C (reset the cycle counter).
constexpr std::uint32_t kPmcrEnable = 1u << 0;
constexpr std::uint32_t kPmcrResetCycleCounter = 1u << 2;
// PMCNTENSET: bit 31 enables the cycle counter.
constexpr std::uint32_t kCycleCounterEnable = 1u << 31;

std::uint32_t read_cycle_counter() {
  std::uint32_t value;
  asm volatile("mrc p15, 0, %0, c9, c13, 0" : "=r"(value));
  return value;
}

}  // namespace

void CycleCounterTimer::enable() {
  if (enabled_) return;
  std::uint32_t control;
  asm volatile("mrc p15, 0, %0, c9, c12, 0" : "=r"(control));
  control |= kPmcrEnable | kPmcrResetCycleCounter;
  asm volatile("mcr p15, 0, %0, c9, c12, 0" ::"r"(control));
  asm volatile("mcr p15, 0, %0, c9, c12, 1" ::"r"(kCycleCounterEnable));
  asm volatile("isb" ::: "memory");
  last_low_ = 0;
  high_ = 0;
  enabled_ = true;
}

std::uint64_t CycleCounterTimer::now_counts() const {
  const std::uint32_t low = read_cycle_counter();
  if (low < last_low_) high_ += std::uint64_t{1} << 32;
  last_low_ = low;
  return high_ | low;
}

void CycleCounterTimer::start(std::int64_t period_ns) {
  enable();
  schedule_.start(now_ns() + period_ns, period_ns);
}

hal::TimerTick CycleCounterTimer::wait_next() {
  hal::TimerTick tick;
  tick.missed_releases = schedule_.skip_past(now_ns());
  tick.release_ns = schedule_.take();
  // The wait reads the counter rarely: under -icount each read ends QEMU's
  // translated block, and a loop of reads made the waits most of a run's
  // host time (zynqmp.forward_path took 5 s, now under 2). Between reads it
  // spins an eighth of what is left, at three instructions and at least
  // one clock an iteration, and at most kSpinIterations (15 us under
  // icount): never past the release, and about 65 reads in a period's wait.
  // Before each read, the idle hint an SMP core gives its sibling (YIELD):
  // under QEMU's TCG, which runs the cores in turn on one virtual clock,
  // it ends this core's turn, so that a program on the RPU's second core
  // (zynqmp.workload's peer) works while this one idles instead of in its
  // cycles; the spins' cap gives it a turn every 15 us or sooner, so that
  // its own waits end close to their deadlines. With the second core off
  // the hint costs one instruction a read.
  constexpr std::uint32_t kSpinIterations = 5'000;
  for (;;) {
    yield_to_other_core();
    const std::int64_t remaining_ns = tick.release_ns - now_ns();
    if (remaining_ns <= 0) break;
    std::uint32_t iterations = static_cast<std::uint32_t>(remaining_ns / ns_per_count_ / 8);
    if (iterations > kSpinIterations) iterations = kSpinIterations;
    while (iterations != 0) {
      iterations -= 1;
      asm volatile("" ::: "memory");
    }
  }
  return tick;
}

}  // namespace cdcr::zynqmp
