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
  period_ns_ = period_ns > 0 ? period_ns : 1;
  next_release_ns_ = clock_.now_ns() + period_ns_;
  overruns_ = 0;
}

hal::TimerTick PosixPeriodicTimer::wait_next() {
  hal::TimerTick tick;
  // A release already in the past is missed, not served late: serving it
  // would start the cycle after its deadline. Every skipped one is counted.
  const std::int64_t now_ns = clock_.now_ns();
  if (next_release_ns_ < now_ns) {
    const std::int64_t behind = (now_ns - next_release_ns_ + period_ns_ - 1) / period_ns_;
    next_release_ns_ += behind * period_ns_;
    tick.missed_releases = behind > 0xFFFFFFFF ? 0xFFFFFFFFu : std::uint32_t(behind);
  }
  overruns_ += tick.missed_releases;
  if (wait_ == ReleaseWait::spin) {
    while (clock_.now_ns() < next_release_ns_) {
    }
  } else {
    const timespec deadline{static_cast<time_t>(next_release_ns_ / kNanosecondsPerSecond),
                            static_cast<long>(next_release_ns_ % kNanosecondsPerSecond)};
    // The deadline is absolute, so a sleep cut short by a signal resumes to
    // the same instant.
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
    }
  }
  tick.release_ns = next_release_ns_;
  next_release_ns_ += period_ns_;
  return tick;
}

}  // namespace cdcr::linux_host
