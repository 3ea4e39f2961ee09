#pragma once
// The releases of a periodic timer: release k at first + k periods, in any
// unit of time (nanoseconds, or the SysTick's periods). Every backend's
// PeriodicTimer keeps its schedule here; what differs is only how it waits.
//
//   A timer that waits for its release (sleep, spin, lockstep) skips the
//   releases already past on arrival and waits for the next: skip_past().
//   A timer that cannot wait (the caller steps it, or an interrupt already
//   woke it late) serves the latest release that has come: skip_to_latest().
// Either way the skipped releases are the missed ones, and take() hands out
// the release served.

#include <cstdint>

namespace cdcr::hal {

class ReleaseSchedule {
 public:
  void start(std::int64_t first_release, std::int64_t period) {
    next_ = first_release;
    period_ = period;
    missed_total_ = 0;
  }

  std::int64_t next_release() const { return next_; }
  std::int64_t period() const { return period_; }
  // Releases missed since start(), at most 2^32 - 1.
  std::uint32_t missed_total() const { return missed_total_; }

  // Skips every release before `now`: the next is then the first at or
  // after it. Returns how many were skipped.
  std::uint32_t skip_past(std::int64_t now) {
    if (period_ <= 0 || next_ >= now) return 0;
    return skip((now - next_ + period_ - 1) / period_);
  }

  // Skips to the latest release at or before `now` (none if the next is
  // still ahead). Returns how many were skipped.
  std::uint32_t skip_to_latest(std::int64_t now) {
    if (period_ <= 0 || now < next_ + period_) return 0;
    return skip((now - next_) / period_);
  }

  // The next release, served; the one a period later becomes the next.
  std::int64_t take() {
    const std::int64_t release = next_;
    next_ += period_;
    return release;
  }

 private:
  std::uint32_t skip(std::int64_t releases) {
    next_ += releases * period_;
    const std::uint32_t missed = releases > 0xFFFFFFFF ? 0xFFFFFFFFu : static_cast<std::uint32_t>(releases);
    missed_total_ += missed;
    return missed;
  }

  std::int64_t next_ = 0;
  std::int64_t period_ = 0;
  std::uint32_t missed_total_ = 0;
};

}  // namespace cdcr::hal
