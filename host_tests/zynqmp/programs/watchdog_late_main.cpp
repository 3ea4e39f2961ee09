// The board's watchdog against cycles that keep running late
// (zynqmp.watchdog_late): every cycle takes 1.5 ms of its 1 ms period, so
// none completes within its period and none kicks the watchdog (board.hpp
// guard). Within the 5 ms timeout the guard finds it expired, reports
// WATCHDOG on the UART and ends QEMU with ExitCode::watchdog_expired (6),
// which the test expects. Coming back from 50 such cycles is a failure
// (status 1). Run under -icount shift=0, as zynqmp.watchdog.

#include <cstdint>

#include <cdcr/zynqmp/console.hpp>

#include "board.hpp"
#include "checks.hpp"

namespace {

namespace zynqmp = cdcr::zynqmp;
namespace r5f = cdcr::boards::zcu102_r5f;
using namespace cdcr::zynqmp_checks;  // check, verdict

r5f::Board board;

void spin_ns(std::int64_t duration_ns) {
  const std::int64_t end_ns = board.timer.now_ns() + duration_ns;
  while (board.timer.now_ns() < end_ns) {
  }
}

}  // namespace

int main() {
  zynqmp::console_write("zynqmp watchdog: every cycle runs 1.5 ms late\n");
  board.start_cycles();
  for (int cycle = 0; cycle < 50; ++cycle) {
    board.run_guarded([](const cdcr::hal::TimerTick&) { spin_ns(1'500'000); });
  }
  check(false, "50 late cycles ran on: the watchdog did not expire");
  return verdict();
}
