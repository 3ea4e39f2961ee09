#pragma once
// Deterministic simulated time: wait_next() jumps the clock to the next
// release instead of sleeping, so a simulated second takes as long as its
// work does and every run is the same. Work takes no simulated time unless
// the caller charges it with advance_by().

#include <cstdint>

#include <cdcr/hal/clock.hpp>
#include <cdcr/hal/release_schedule.hpp>

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

  // Release 1 is one period after start().
  void start(std::int64_t period_ns) override { schedule_.start(clock_.now_ns() + period_ns, period_ns); }

  // The releases already past are missed; the clock jumps to the next.
  hal::TimerTick wait_next() override {
    hal::TimerTick tick;
    tick.missed_releases = schedule_.skip_past(clock_.now_ns());
    clock_.advance_to(schedule_.next_release());
    tick.release_ns = schedule_.take();
    return tick;
  }

  std::int64_t period_ns() const override { return schedule_.period(); }
  std::uint32_t overruns() const override { return schedule_.missed_total(); }

 private:
  LockstepClock& clock_;
  hal::ReleaseSchedule schedule_;
};

}  // namespace cdcr::sim
