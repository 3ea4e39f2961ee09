// cdcr/cortexm/mps2.h: the board's semihosting console and SysTick timer
// for C programs.

#include "cdcr/cortexm/mps2.h"

#include "cdcr/cortexm/semihosting.hpp"
#include "cdcr/cortexm/systick.hpp"

namespace {

constexpr std::uint32_t kCoreClockHz = 25'000'000;  // both MPS2 boards

cdcr::cortexm::SysTickTimer& timer() {
  static cdcr::cortexm::SysTickTimer instance(kCoreClockHz);
  return instance;
}

}  // namespace

extern "C" {

void cdcr_mps2_console_write(const char* text) { cdcr::cortexm::console_write(text); }

void cdcr_mps2_timer_start(int64_t period_ns) {
  cdcr::cortexm::attach_systick(timer());
  timer().start(period_ns);
}

int64_t cdcr_mps2_timer_wait_next(void) { return timer().wait_next().release_ns; }

int64_t cdcr_mps2_now_ns(void) { return timer().now_ns(); }

}  // extern "C"
