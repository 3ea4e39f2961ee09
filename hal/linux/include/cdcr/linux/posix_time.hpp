#pragma once
// Time on a Linux host: CLOCK_MONOTONIC, and periodic releases slept to with
// clock_nanosleep(TIMER_ABSTIME) so that neither the work nor the sleep's own
// latency accumulates into drift; or spun to, for a core given to the
// runtime alone.

#include <cstdint>

#include <cdcr/hal/clock.hpp>
#include <cdcr/hal/release_schedule.hpp>

namespace cdcr::linux_host {

class PosixMonotonicClock final : public hal::MonotonicClock {
 public:
  std::int64_t now_ns() const override;
};

// How a release is waited for. sleep gives the core away between cycles;
// on a virtual machine, or a core that other threads share, the cycle after
// the sleep then often starts on a cold cache or a descheduled core, which
// on the README's benchmark host tripled a cycle's p99 at 1 kHz. spin reads
// the clock until the release, keeping the core and its caches: for a core
// reserved for the runtime (isolcpus, or a dedicated board computer), at
// the price of the whole core.
enum class ReleaseWait { sleep, spin };

class PosixPeriodicTimer final : public hal::PeriodicTimer {
 public:
  explicit PosixPeriodicTimer(const hal::MonotonicClock& clock, ReleaseWait wait = ReleaseWait::sleep)
      : clock_(clock), wait_(wait) {}

  // Release 1 is one period after start().
  void start(std::int64_t period_ns) override;
  hal::TimerTick wait_next() override;
  std::int64_t period_ns() const override { return schedule_.period(); }
  std::uint32_t overruns() const override { return schedule_.missed_total(); }

 private:
  const hal::MonotonicClock& clock_;
  ReleaseWait wait_;
  hal::ReleaseSchedule schedule_;
};

}  // namespace cdcr::linux_host
