#pragma once
// Time as the runtime sees it. Destructors are protected and non-virtual:
// backends are statically allocated and never deleted through an interface,
// so a bare-metal build needs no operator delete.

#include <cstdint>

#include "cdcr/hal/interface.hpp"

namespace cdcr::hal {

// Nanoseconds since an arbitrary epoch; never goes backwards.
class MonotonicClock : public Interface {
 public:
  virtual std::int64_t now_ns() const = 0;

 protected:
  ~MonotonicClock() = default;
};

struct TimerTick {
  std::int64_t release_ns = 0;       // the absolute release time this wake-up belongs to
  std::uint32_t missed_releases = 0; // releases skipped because the caller came back too late
};

// Absolute-time periodic releases: release k is start + k * period, so lateness
// in one cycle never shifts the following ones (no drift).
class PeriodicTimer : public Interface {
 public:
  virtual void start(std::int64_t period_ns) = 0;
  // Blocks until the next release that is still in the future, and reports
  // how many were missed on the way.
  virtual TimerTick wait_next() = 0;
  virtual std::int64_t period_ns() const = 0;
  // Total releases missed since start().
  virtual std::uint32_t overruns() const = 0;

 protected:
  ~PeriodicTimer() = default;
};

}  // namespace cdcr::hal
