#pragma once
// Deterministic simulated time: wait_next() jumps the clock to the next
// release instead of sleeping, so a simulated second takes as long as its
// work does and every run is the same. Work takes no simulated time unless
// the caller charges it with advance_by().

#include <cstdint>

#include <cdcr/hal/clock.hpp>

namespace cdcr::sim {

class LockstepClock final : public hal::MonotonicClock {
 public:
  std::int64_t now_ns() const override { return now_ns_; }
  void advance_by(std::int64_t ns) {
    if (ns > 0) now_ns_ += ns;
  }
  void advance_to(std::int64_t ns) {
    if (ns > now_ns_) now_ns_ = ns;
  }

 private:
  std::int64_t now_ns_ = 0;
};

class LockstepTimer final : public hal::PeriodicTimer {
 public:
  explicit LockstepTimer(LockstepClock& clock) : clock_(clock) {}

  void start(std::int64_t period_ns) override {
    period_ns_ = period_ns;
    next_release_ns_ = clock_.now_ns() + period_ns;
    overruns_ = 0;
  }

  hal::TimerTick wait_next() override {
    hal::TimerTick tick;
    while (next_release_ns_ < clock_.now_ns()) {
      next_release_ns_ += period_ns_;
      tick.missed_releases += 1;
    }
    overruns_ += tick.missed_releases;
    clock_.advance_to(next_release_ns_);
    tick.release_ns = next_release_ns_;
    next_release_ns_ += period_ns_;
    return tick;
  }

  std::int64_t period_ns() const override { return period_ns_; }
  std::uint32_t overruns() const override { return overruns_; }

 private:
  LockstepClock& clock_;
  std::int64_t period_ns_ = 0;
  std::int64_t next_release_ns_ = 0;
  std::uint32_t overruns_ = 0;
};

}  // namespace cdcr::sim
