#pragma once
// The HAL made of a board's callbacks (callbacks.h): the backend behind the
// C API, for boards that integrate the runtime from C. Time is the board's
// clock, and the board steps the runtime itself once per period, so the
// timer keeps the schedule only (lateness shows as jitter and missed
// releases); the bus is the board's send and receive, if it has them; the
// model image is the board's, in place; console lines go to the board's
// callback or nowhere. Nothing allocates.

#include <cstdint>

#include "cdcr/callbacks/callbacks.h"
#include "cdcr/hal/hal.hpp"
#include "cdcr/hal/release_schedule.hpp"

namespace cdcr::callbacks {

class CallbackClock final : public hal::MonotonicClock {
 public:
  explicit CallbackClock(const cdcr_callbacks& callbacks) : callbacks_(callbacks) {}
  std::int64_t now_ns() const override;

 private:
  const cdcr_callbacks& callbacks_;
};

// Release 0 is the first wait_next()'s time; each later call serves the
// latest release that has come. Period 0: every call is its own release.
class SteppedTimer final : public hal::PeriodicTimer {
 public:
  explicit SteppedTimer(const hal::MonotonicClock& clock) : clock_(clock) {}
  void start(std::int64_t period_ns) override;
  hal::TimerTick wait_next() override;
  std::int64_t period_ns() const override { return period_ns_; }
  std::uint32_t overruns() const override { return schedule_.missed_total(); }

 private:
  const hal::MonotonicClock& clock_;
  std::int64_t period_ns_ = 0;
  bool started_ = false;
  hal::ReleaseSchedule schedule_;
};

// The board's can_send and can_receive; without them frames sent go nowhere
// and none arrive.
class CallbackBus final : public hal::CanBus {
 public:
  explicit CallbackBus(const cdcr_callbacks& callbacks) : callbacks_(callbacks) {}
  hal::CanStatus send(const hal::CanFrame& frame) override;
  hal::CanStatus receive(hal::CanFrame& frame) override;
  // Without a bus of the board's there is nothing foreign to filter.
  bool set_filters(const hal::CanFilter* filters, std::size_t count) override;
  hal::CanErrorCounters error_counters() const override { return counters_; }

 private:
  const cdcr_callbacks& callbacks_;
  hal::CanErrorCounters counters_;
};

// One of the CiA 402 drives' buses: the board's drives_can_send and
// drives_can_receive for that bus index.
class CallbackDrivesBus final : public hal::CanBus {
 public:
  CallbackDrivesBus(const cdcr_callbacks& callbacks, int bus) : callbacks_(callbacks), bus_(bus) {}
  hal::CanStatus send(const hal::CanFrame& frame) override;
  hal::CanStatus receive(hal::CanFrame& frame) override;
  bool set_filters(const hal::CanFilter*, std::size_t) override { return true; }
  hal::CanErrorCounters error_counters() const override { return counters_; }

 private:
  const cdcr_callbacks& callbacks_;
  int bus_;
  hal::CanErrorCounters counters_;
};

class ImageStorage final : public hal::ModelStorage {
 public:
  ImageStorage(const std::uint8_t* data, std::uint32_t size) : region_{data, data != nullptr ? size : 0} {}
  hal::MemoryRegion model_region() const override { return region_; }

 private:
  hal::MemoryRegion region_;
};

class CallbackConsole final : public hal::Console {
 public:
  explicit CallbackConsole(const cdcr_callbacks& callbacks) : callbacks_(callbacks) {}
  void write_line(const char* line) override;

 private:
  const cdcr_callbacks& callbacks_;
};

// The whole backend, over its own copy of the callbacks.
class CallbackHal {
 public:
  CallbackHal(const cdcr_callbacks& callbacks, const std::uint8_t* model_image, std::uint32_t model_image_size)
      : callbacks_(callbacks),
        clock_(callbacks_),
        timer_(clock_),
        bus_(callbacks_),
        storage_(model_image, model_image_size),
        console_(callbacks_) {}
  CallbackHal(const CallbackHal&) = delete;
  CallbackHal& operator=(const CallbackHal&) = delete;

  hal::Hal hal() { return hal::Hal{clock_, timer_, bus_, storage_, console_}; }
  SteppedTimer& timer() { return timer_; }
  const cdcr_callbacks& callbacks() const { return callbacks_; }

 private:
  cdcr_callbacks callbacks_;  // first: the parts below keep references to it
  CallbackClock clock_;
  SteppedTimer timer_;
  CallbackBus bus_;
  ImageStorage storage_;
  CallbackConsole console_;
};

}  // namespace cdcr::callbacks
