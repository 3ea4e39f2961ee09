#pragma once
// One Runtime::run_cycle counted on the R5F's cycle counter: under -icount
// shift=0 it counts instructions. The barriers keep the compiler from
// moving work into or out of the counted region.

#include <cstdint>

#include <cdcr/firmware/runtime.hpp>

namespace cdcr::zynqmp_checks {

template <typename Timer>
std::uint64_t counted_run_cycle(const Timer& timer, firmware::Runtime& runtime, const hal::TimerTick& tick) {
  asm volatile("" ::: "memory");
  const std::uint64_t start = timer.now_counts();
  asm volatile("" ::: "memory");
  runtime.run_cycle(tick);
  asm volatile("" ::: "memory");
  const std::uint64_t counts = timer.now_counts() - start;
  asm volatile("" ::: "memory");
  return counts;
}

}  // namespace cdcr::zynqmp_checks
