#pragma once
// What the programs that measure the runtime on the MPS2 boards
// (cycle_budget, update_budget) drive it with: the peer of peer_workload.hpp
// on the board's mailbox bus, and a cycle counted in instructions.

#include <cstdint>

#include <cdcr/cortexm/semihosting.hpp>
#include <cdcr/firmware/runtime.hpp>

#include "board.hpp"
#include "instruction_count.hpp"
#include "peer_workload.hpp"

namespace cdcr::qemu_programs {

namespace model = cdcr::model;
namespace firmware = cdcr::firmware;
namespace protocol = cdcr::firmware::protocol;

inline std::uint32_t counted_cycle(const boards::mps2::InstructionCounter& counter, boards::mps2::Board& board,
                                   firmware::Runtime& runtime) {
  const hal::TimerTick tick{board.timer.now_ns(), 0};
  return counter.instructions([&] { run_cycle_opaque(runtime, tick); });
}

// The start every measuring program makes: SysTick counting at
// kCountingPeriodNs, the runtime booted into RUN, and the board's image bound
// to `correction`. False, with the reason printed, when one of them fails.
inline bool start_counting(boards::mps2::Board& board, firmware::Runtime& runtime,
                           firmware::Correction& correction, model::ImageView& image) {
  cortexm::attach_systick(board.timer);
  board.timer.start(boards::mps2::kCountingPeriodNs);
  if (runtime.init() != firmware::RuntimeState::run) {
    cortexm::console_write("FAIL: the runtime did not boot into RUN\n");
    return false;
  }
  if (!bind_board_image(board, correction, image)) {
    cortexm::console_write("FAIL: cannot bind the image\n");
    return false;
  }
  return true;
}

// `worst cycle: N instructions over C cycles (budget B)`, the line the
// budget tests and tools/bench read.
inline void report_worst_cycle(std::uint32_t worst, std::uint32_t cycles) {
  cortexm::console_write("worst cycle: ");
  cortexm::console_write_int(static_cast<std::int32_t>(worst));
  cortexm::console_write(" instructions over ");
  cortexm::console_write_int(static_cast<std::int32_t>(cycles));
  cortexm::console_write(" cycles (budget ");
  cortexm::console_write_int(static_cast<std::int32_t>(boards::mps2::kCycleBudgetInstructions));
  cortexm::console_write(")\n");
}

// `worst <phase> cycle: N instructions over C cycles`, a line per phase.
inline void report_phases(const char* const* names, const std::uint32_t* worst, const std::uint32_t* cycles,
                          int phases) {
  for (int p = 0; p < phases; ++p) {
    cortexm::console_write("worst ");
    cortexm::console_write(names[p]);
    cortexm::console_write(" cycle: ");
    cortexm::console_write_int(static_cast<std::int32_t>(worst[p]));
    cortexm::console_write(" instructions over ");
    cortexm::console_write_int(static_cast<std::int32_t>(cycles[p]));
    cortexm::console_write(" cycles\n");
  }
}

}  // namespace cdcr::qemu_programs
