#pragma once
// Instruction counts on QEMU's MPS2 boards, for the programs that measure
// the runtime (cycle_bench, cycle_budget, update_budget). Under
// `-icount shift=10` virtual time advances 2^10 ns per instruction, so the
// SysTick ticks between two reads of the timer count the instructions
// between them, deterministically, whatever the host is doing.

#include <cstdint>

#include "board.hpp"

namespace cdcr::boards::mps2 {

inline constexpr int kIcountShift = 10;
// A period far longer than anything measured keeps SysTick exceptions (and
// their instructions) out of the counts.
inline constexpr std::int64_t kCountingPeriodNs = 600'000'000;

// The cycle budget the boards are held to, in instructions.
#if defined(__ARM_FP) && !(__ARM_FP & 0x8)
inline constexpr std::uint32_t kCycleBudgetInstructions = 120'000;  // Cortex-M4F
#else
inline constexpr std::uint32_t kCycleBudgetInstructions = 80'000;  // Cortex-M7
#endif

inline std::uint32_t ticks_to_instructions(std::uint64_t ticks) {
  const std::uint64_t ns = ticks * (1'000'000'000u / kCoreClockHz);
  return static_cast<std::uint32_t>((ns + (1u << (kIcountShift - 1))) >> kIcountShift);
}

// Counts work() between two timer reads, less the reads' own cost
// (calibrate() first, with the timer running at kCountingPeriodNs). The
// compiler barriers keep the work inside the counted region; a caller that
// must keep the compiler from moving the work's own code puts it behind a
// noinline call.
class InstructionCounter {
 public:
  explicit InstructionCounter(const cortexm::SysTickTimer& timer) : timer_(timer) {}

  // The ticks of `empty` counted as work: what every count leaves out.
  template <typename Work>
  void calibrate(Work&& empty) {
    overhead_ticks_ = ticks(empty);
  }
  void calibrate() {
    calibrate([] {});
  }

  template <typename Work>
  std::uint64_t ticks(Work&& work) const {
    asm volatile("" ::: "memory");
    const std::uint64_t start = timer_.now_ticks();
    asm volatile("" ::: "memory");
    work();
    asm volatile("" ::: "memory");
    const std::uint64_t end = timer_.now_ticks();
    asm volatile("" ::: "memory");
    return end - start;
  }

  template <typename Work>
  std::uint32_t instructions(Work&& work) const {
    const std::uint64_t counted = ticks(work);
    return ticks_to_instructions(counted > overhead_ticks_ ? counted - overhead_ticks_ : 0);
  }

 private:
  const cortexm::SysTickTimer& timer_;
  std::uint64_t overhead_ticks_ = 0;
};

}  // namespace cdcr::boards::mps2
