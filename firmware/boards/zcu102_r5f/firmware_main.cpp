// The runtime as the R5F board runs it: the host's bus on can0 and the
// drives' on can1, both at 1 Mbit/s; the computed bus budget stated (and a
// configuration that does not fit refused); boot (validate the image in
// .cdcr_model), then one cycle per 1 ms of the cycle counter, forever, under
// the watchdog (board.hpp). Fallback geometry is the robot's design
// geometry. Under QEMU nothing sends cable frames, so the UART shows the
// boot state and then FAULT (stale input) after kStaleInputCycles.

#include <cdcr/firmware/runtime.hpp>

#include "board.hpp"

namespace {

cdcr::boards::zcu102_r5f::Board board;
cdcr::boards::zcu102_r5f::DrivesBus drives;
cdcr::firmware::Runtime runtime(board.hal(drives), cdcr::firmware::Geometry::prototype());

}  // namespace

int main() {
  if (!cdcr::boards::zcu102_r5f::state_bus_budgets()) {
    board.console.write_line("the buses do not fit this configuration: not starting");
    cdcr::zynqmp::exit(cdcr::zynqmp::ExitCode::failure);
  }
  // A controller that does not come up leaves the runtime without that bus:
  // it runs on and reports stale input, as with drives that never speak.
  if (!board.start_can()) board.console.write_line("can0 did not start");
  if (!drives.start()) board.console.write_line("can1 did not start");
  runtime.init();
  board.start_cycles();
  for (;;) board.run_guarded([](const cdcr::hal::TimerTick& tick) { runtime.run_cycle(tick); });
}
