// The board's watchdog (zynqmp.watchdog): the TTC watchdog driver against
// QEMU's TTC0, then the board's cycle loop under it (board.hpp run_guarded).
//   1. The driver: the count advances at the TTC's clock, a kick restarts
//      it, the flag rises after the timeout without a kick and stays up.
//   2. Healthy cycles: 200 cycles, each with 600 us of work, never expire
//      it.
//   3. One late cycle (1.5 ms of work; with the wait and the next cycle
//      under the 5 ms timeout): its next release is missed, the watchdog
//      does not expire.
//   4. A hung cycle (spins 10 ms): the board's guard finds the watchdog
//      expired, reports WATCHDOG on the UART and ends QEMU with
//      ExitCode::watchdog_expired (6), which the test expects. Coming back
//      from that cycle is a failure (status 1).
// Run under -icount shift=0: the TTC counts QEMU's virtual clock, which the
// instructions advance, so every figure repeats exactly.

#include <cstdint>

#include <cdcr/zynqmp/console.hpp>
#include <cdcr/zynqmp/ttc_watchdog.hpp>
#include <cdcr/zynqmp/zcu102.hpp>

#include "board.hpp"
#include "checks.hpp"

namespace {

namespace zynqmp = cdcr::zynqmp;
namespace r5f = cdcr::boards::zcu102_r5f;
using namespace cdcr::zynqmp_checks;  // check, check_equal, print, verdict

r5f::Board board;

void spin_ns(std::int64_t duration_ns) {
  const std::int64_t end_ns = board.timer.now_ns() + duration_ns;
  while (board.timer.now_ns() < end_ns) {
  }
}

void check_driver() {
  // 5 ms at 133 MHz is 665,000 counts: prescaled by 4096 to 162 (4.989 ms),
  // the counter's range 2.02 s.
  constexpr zynqmp::TtcTimeout kTimeout = zynqmp::ttc_timeout(zynqmp::kTtcClockHz, r5f::kWatchdogTimeoutNs);
  static_assert(kTimeout.prescaled && kTimeout.prescale_exponent == 11 && kTimeout.timeout_counts == 162,
                "5 ms at 133 MHz / 4096");
  static_assert(zynqmp::ttc_timeout(zynqmp::kTtcClockHz, 0).timeout_counts == 0, "no timeout of 0");
  static_assert(zynqmp::ttc_timeout(zynqmp::kTtcClockHz, 1'000'000'000ull).timeout_counts == 0,
                "1 s leaves the counter no 256 timeouts of range, even prescaled by 65536");

  zynqmp::TtcWatchdog& watchdog = board.watchdog;
  check(!watchdog.start(1'000'000'000ull), "a timeout beyond the counter is refused");
  board.timer.enable();
  check(watchdog.start(r5f::kWatchdogTimeoutNs), "a 5 ms timeout is taken");
  spin_ns(1'000'000);
  // 1 ms at 133 MHz / 4096: 32.5 counts.
  const std::uint32_t after_1ms = watchdog.count();
  print("TTC0 after 1 ms: ", after_1ms, " counts (32 expected at 133 MHz / 4096)\n");
  check_equal(after_1ms, 32, "the TTC counts 133 MHz / 4096");
  check(!watchdog.expired(), "not expired 1 ms after the start");
  watchdog.kick();
  check_equal(watchdog.count(), 0, "a kick restarts the count");
  spin_ns(2'500'000);
  check(!watchdog.expired(), "not expired 2.5 ms after a kick");
  watchdog.kick();
  spin_ns(4'800'000);
  check(!watchdog.expired(), "not expired 4.8 ms after a kick");
  spin_ns(250'000);
  check(watchdog.expired(), "expired 5.05 ms after the last kick");
  watchdog.kick();
  check(watchdog.expired(), "an expiry stays until the next start");
  check(watchdog.start(r5f::kWatchdogTimeoutNs) && !watchdog.expired(), "a start clears the expiry");
  watchdog.stop();
  spin_ns(6'000'000);
  check(!watchdog.expired(), "a stopped watchdog does not expire");
}

}  // namespace

int main() {
  zynqmp::console_write("zynqmp watchdog: TTC0 as the cycle loop's watchdog\n");
  check_driver();

  board.start_cycles();
  constexpr int kHealthyCycles = 200;
  for (int cycle = 0; cycle < kHealthyCycles; ++cycle) {
    board.run_guarded([](const cdcr::hal::TimerTick&) { spin_ns(600'000); });
  }
  check_equal(board.timer.overruns(), 0, "no release missed by cycles of 600 us");
  print("watchdog healthy: ", kHealthyCycles, " cycles of 600 us, not expired\n");

  board.run_guarded([](const cdcr::hal::TimerTick&) { spin_ns(1'500'000); });
  for (int cycle = 0; cycle < 10; ++cycle) board.run_guarded([](const cdcr::hal::TimerTick&) { spin_ns(600'000); });
  check_equal(board.timer.overruns(), 1, "a cycle of 1.5 ms misses one release");
  print("one late cycle: ", board.timer.overruns(), " release missed, not expired\n");
  if (failures != 0) return verdict();

  zynqmp::console_write("a cycle hangs for 10 ms\n");
  board.run_guarded([](const cdcr::hal::TimerTick&) { spin_ns(10'000'000); });
  check(false, "the board came back from a hung cycle: the watchdog did not expire");
  return verdict();
}
