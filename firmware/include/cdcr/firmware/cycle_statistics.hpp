#pragma once
// The runtime's counters since init: what STATUS and STATS report, and the
// C API's status.

#include <cstdint>

#include "cdcr/hal/clock.hpp"

namespace cdcr::firmware {

struct CycleStatistics {
  std::uint32_t cycles = 0;
  std::uint32_t overruns = 0;  // cycles longer than the period plus releases the timer reports missed
  std::int64_t execution_max_ns = 0;
  std::int64_t execution_total_ns = 0;
  std::int64_t jitter_max_ns = 0;  // start of work after its release time
  std::uint32_t rejected_frames = 0;
  std::uint32_t rejected_cable_sets = 0;
  std::uint32_t stale_events = 0;
  std::uint32_t poses_published = 0;
  std::uint32_t targets_received = 0;

  std::int64_t execution_mean_ns() const { return cycles == 0 ? 0 : execution_total_ns / cycles; }

  // A cycle of `tick`'s release that ran from start_ns to end_ns on the HAL
  // clock, with the timer's period (0: none).
  void record_cycle(const hal::TimerTick& tick, std::int64_t start_ns, std::int64_t end_ns, std::int64_t period_ns) {
    const std::int64_t execution_ns = end_ns - start_ns;
    const std::int64_t jitter_ns = start_ns - tick.release_ns;
    cycles += 1;
    execution_total_ns += execution_ns;
    if (execution_ns > execution_max_ns) execution_max_ns = execution_ns;
    if (jitter_ns > jitter_max_ns) jitter_max_ns = jitter_ns;
    overruns += tick.missed_releases;
    if (execution_ns > period_ns && period_ns > 0) overruns += 1;
  }
};

}  // namespace cdcr::firmware
