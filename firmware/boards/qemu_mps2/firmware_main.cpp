// The runtime as a board runs it: boot (validate the image in .cdcr_model),
// then one cycle per 1 ms SysTick period, forever. Fallback geometry is the
// robot's design geometry. On QEMU nothing sends cable frames, so the log
// shows the boot state and then FAULT (stale input) after kStaleInputCycles.

#include <cdcr/firmware/runtime.hpp>

#include "board.hpp"

namespace {

cdcr::boards::mps2::Board board;
cdcr::firmware::Runtime runtime(board.hal(), cdcr::firmware::Geometry::prototype());

}  // namespace

int main() {
  cdcr::cortexm::attach_systick(board.timer);
  runtime.init();
  board.timer.start(cdcr::boards::mps2::kCyclePeriodNs);
  for (;;) runtime.run_cycle(board.timer.wait_next());
}
