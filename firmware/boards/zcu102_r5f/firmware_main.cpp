// The runtime as the R5F board runs it: can0 onto the bus at 1 Mbit/s, boot
// (validate the image in .cdcr_model), then one cycle per 1 ms of the cycle
// counter, forever, under the watchdog (board.hpp). Fallback geometry is the robot's design geometry. Under
// QEMU nothing sends cable frames, so the UART shows the boot state and
// then FAULT (stale input) after kStaleInputCycles.

#include <cdcr/firmware/runtime.hpp>

#include "board.hpp"

namespace {

cdcr::boards::zcu102_r5f::Board board;
cdcr::firmware::Runtime runtime(board.hal(), cdcr::firmware::Geometry::prototype());

}  // namespace

int main() {
  // A controller that does not come up leaves the runtime without a bus: it
  // runs on and reports stale input, as with drives that never speak.
  if (!board.start_can()) board.console.write_line("can0 did not start");
  runtime.init();
  board.start_cycles();
  for (;;) board.run_guarded([](const cdcr::hal::TimerTick& tick) { runtime.run_cycle(tick); });
}
