#include "cdcr/linux/posix_time.hpp"

#include <cerrno>
#include <ctime>

namespace cdcr::linux_host {

namespace {

constexpr std::int64_t kNanosecondsPerSecond = 1'000'000'000;

std::int64_t monotonic_now_ns() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return std::int64_t(now.tv_sec) * kNanosecondsPerSecond + now.tv_nsec;
}

}  // namespace

std::int64_t PosixMonotonicClock::now_ns() const { return monotonic_now_ns(); }

void PosixPeriodicTimer::start(std::int64_t period_ns) {
  const std::int64_t period = period_ns > 0 ? period_ns : 1;
  schedule_.start(clock_.now_ns() + period, period);
}

hal::TimerTick PosixPeriodicTimer::wait_next() {
  hal::TimerTick tick;
  // A release already in the past is missed, not served late: serving it
  // would start the cycle after its deadline. Every skipped one is counted.
  tick.missed_releases = schedule_.skip_past(clock_.now_ns());
  const std::int64_t release_ns = schedule_.take();
  if (wait_ == ReleaseWait::spin) {
    while (clock_.now_ns() < release_ns) {
    }
  } else {
    const timespec deadline{static_cast<time_t>(release_ns / kNanosecondsPerSecond),
                            static_cast<long>(release_ns % kNanosecondsPerSecond)};
    // The deadline is absolute, so a sleep cut short by a signal resumes to
    // the same instant.
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
    }
  }
  tick.release_ns = release_ns;
  return tick;
}

}  // namespace cdcr::linux_host
