// The runtime as the R5F board runs it: the host's bus on can0 and the
// drives' on can1, both at 1 Mbit/s, the protocol's identifiers from
// CDCR_R5F_CAN_ID_BASE (default 0x100; another base for a bus shared with
// CANopen, firmware/protocol.md); the computed bus budget stated (and a
// configuration that does not fit refused); boot (validate the image in
// .cdcr_model), then one cycle per 1 ms of the cycle counter, forever, under
// the watchdog (board.hpp). Fallback geometry is the robot's design
// geometry. Without drives on the bus the UART shows the boot state and
// then FAULT (stale input) after kStaleInputCycles.

#include <cdcr/firmware/protocol/messages.hpp>
#include <cdcr/firmware/runtime.hpp>
#include <cdcr/hal/shifted_can_bus.hpp>

#include "board.hpp"

#ifndef CDCR_R5F_CAN_ID_BASE
#define CDCR_R5F_CAN_ID_BASE 0x100
#endif

namespace {

namespace protocol = cdcr::firmware::protocol;
constexpr std::uint32_t kCanIdBase = CDCR_R5F_CAN_ID_BASE;
static_assert(protocol::is_valid_id_base(kCanIdBase), "CDCR_R5F_CAN_ID_BASE: a multiple of 8 up to 0x780");

cdcr::boards::zcu102_r5f::Board board;
cdcr::boards::zcu102_r5f::DrivesBus drives;
cdcr::hal::ShiftedCanBus host_bus(board.can, protocol::id_offset(kCanIdBase));
cdcr::hal::ShiftedCanBus drives_bus(drives.can, protocol::id_offset(kCanIdBase));
cdcr::firmware::Runtime runtime(board.hal(host_bus, drives_bus), cdcr::firmware::Geometry::prototype());

}  // namespace

int main() {
  // A controller that does not come up leaves the runtime without that bus:
  // it runs on and reports stale input, as with drives that never speak.
  if (!board.start_can()) board.console.write_line("can0 did not start");
  if (!drives.start()) board.console.write_line("can1 did not start");
  runtime.init();
  // The budget of the robot init loaded (the image's, or the fallback's),
  // before the first cycle puts a frame on either bus.
  if (!cdcr::boards::zcu102_r5f::state_bus_budgets(runtime.geometry().segment_count,
                                                   runtime.publish_rates())) {
    board.console.write_line("the buses do not fit this configuration: not starting");
    cdcr::zynqmp::exit(cdcr::zynqmp::ExitCode::failure);
  }
  board.start_cycles();
  for (;;) board.run_guarded([](const cdcr::hal::TimerTick& tick) { runtime.run_cycle(tick); });
}
