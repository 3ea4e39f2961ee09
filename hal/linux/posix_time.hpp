#pragma once
// Time on a Linux host: CLOCK_MONOTONIC, and periodic releases slept to with
// clock_nanosleep(TIMER_ABSTIME) so that neither the work nor the sleep's own
// latency accumulates into drift.

#include <cstdint>

#include <cdcr/hal/clock.hpp>

namespace cdcr::linux_host {

class PosixMonotonicClock final : public hal::MonotonicClock {
 public:
  std::int64_t now_ns() const override;
};

class PosixPeriodicTimer final : public hal::PeriodicTimer {
 public:
  explicit PosixPeriodicTimer(const hal::MonotonicClock& clock) : clock_(clock) {}

  // Release 1 is one period after start().
  void start(std::int64_t period_ns) override;
  hal::TimerTick wait_next() override;
  std::int64_t period_ns() const override { return period_ns_; }
  std::uint32_t overruns() const override { return overruns_; }

 private:
  const hal::MonotonicClock& clock_;
  std::int64_t period_ns_ = 0;
  std::int64_t next_release_ns_ = 0;
  std::uint32_t overruns_ = 0;
};

}  // namespace cdcr::linux_host
