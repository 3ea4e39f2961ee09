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

// How long before a release a warm-up starts (set_warm_up): reading a model
// at the runtime's capacity (about 60 KB) from memory takes 10 to 15 us,
// and the rest of the lead absorbs the sleep's own wake-up latency.
inline constexpr std::int64_t kWarmUpLeadNs = 40'000;

class PosixPeriodicTimer final : public hal::PeriodicTimer {
 public:
  explicit PosixPeriodicTimer(const hal::MonotonicClock& clock) : clock_(clock) {}

  // Release 1 is one period after start().
  void start(std::int64_t period_ns) override;
  // Wake `lead_ns` before each release, call `hook`, then wait out the rest
  // busy: a cycle that starts after a millisecond of sleep finds its data
  // out of the caches, and a second sleep would add the kernel's wake-up
  // latency back. 0 (the default) sleeps straight to the release.
  void set_warm_up(std::int64_t lead_ns, void (*hook)(void*), void* context);
  hal::TimerTick wait_next() override;
  std::int64_t period_ns() const override { return period_ns_; }
  std::uint32_t overruns() const override { return overruns_; }

 private:
  const hal::MonotonicClock& clock_;
  std::int64_t period_ns_ = 0;
  std::int64_t next_release_ns_ = 0;
  std::uint32_t overruns_ = 0;
  std::int64_t warm_up_lead_ns_ = 0;
  void (*warm_up_hook_)(void*) = nullptr;
  void* warm_up_context_ = nullptr;
};

}  // namespace cdcr::linux_host
