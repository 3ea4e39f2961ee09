#pragma once
// What the programs that hold every cycle to the board's budget
// (cycle_budget, update_budget) keep of their counted cycles: the worst,
// how many ran, how many went over the budget and how many in RUN
// published no pose; and the lines that report them.

#include <algorithm>
#include <cstdint>

#include <cdcr/cortexm/semihosting.hpp>
#include <cdcr/firmware/runtime.hpp>

#include "board.hpp"
#include "instruction_count.hpp"
#include "workload.hpp"

namespace cdcr::qemu_programs {

class CycleTally {
 public:
  // One Runtime::run_cycle, counted in instructions (counted_cycle) and
  // tallied; returns its instructions.
  std::uint32_t run_counted(const boards::mps2::InstructionCounter& counter, boards::mps2::Board& board,
                            firmware::Runtime& runtime) {
    const std::uint32_t published = runtime.statistics().poses_published;
    const std::uint32_t instructions = counted_cycle(counter, board, runtime);
    worst_ = std::max(worst_, instructions);
    last_over_budget_ = instructions > boards::mps2::kCycleBudgetInstructions;
    if (last_over_budget_) ++over_budget_;
    if (poses_expected_ && runtime.state() == firmware::RuntimeState::run &&
        runtime.statistics().poses_published != published + 1) {
      ++poses_missing_;
    }
    last_instructions_ = instructions;
    ++cycles_run_;
    return instructions;
  }

  std::uint32_t cycles_run() const { return cycles_run_; }
  // Whether a cycle in RUN must publish a pose (not while drives behind
  // Hal::drives start: the runtime is in RUN from init, before their first
  // positions).
  void expect_poses(bool expected) { poses_expected_ = expected; }

  // Whether the cycle just counted went over the budget, as one of the
  // first `how_many` to: a line each for those tells which work is
  // under-charged without flooding the console.
  bool among_first_over_budget(std::uint32_t how_many) const { return last_over_budget_ && over_budget_ <= how_many; }

  // `over budget: cycle N<what>, I instructions, IK units U` for the cycle
  // just counted; what() writes what the cycle did, the caller ends the line.
  template <typename What>
  void print_over_budget(const firmware::Runtime& runtime, What&& what) const {
    cortexm::console_write("over budget: cycle ");
    cortexm::console_write_int(static_cast<std::int32_t>(cycles_run_ - 1));
    what();
    cortexm::console_write(", ");
    cortexm::console_write_int(static_cast<std::int32_t>(last_instructions_));
    cortexm::console_write(" instructions, IK units ");
    cortexm::console_write_int(static_cast<std::int32_t>(runtime.ik_units_last_cycle()));
  }

  // `worst cycle: ...` (report_worst_cycle), then a FAIL line for cycles
  // over the budget and one for cycles in RUN without a pose; false on
  // either.
  bool report() const {
    report_worst_cycle(worst_, cycles_run_);
    bool ok = true;
    if (over_budget_ > 0) {
      cortexm::console_write("FAIL: cycles over budget: ");
      cortexm::console_write_int(static_cast<std::int32_t>(over_budget_));
      cortexm::console_write("\n");
      ok = false;
    }
    if (poses_missing_ > 0) {
      cortexm::console_write("FAIL: cycles in RUN without a pose: ");
      cortexm::console_write_int(static_cast<std::int32_t>(poses_missing_));
      cortexm::console_write("\n");
      ok = false;
    }
    return ok;
  }

 private:
  std::uint32_t worst_ = 0;
  std::uint32_t cycles_run_ = 0;
  std::uint32_t over_budget_ = 0;
  std::uint32_t poses_missing_ = 0;
  std::uint32_t last_instructions_ = 0;
  bool last_over_budget_ = false;
  bool poses_expected_ = true;
};

}  // namespace cdcr::qemu_programs
