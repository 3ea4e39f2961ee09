#pragma once
// A streamed target's step (IkSolver::retarget()): one damped step first
// thing in the next run(), on the linearisation and the rows in hand, while
// the evaluation at a newer point goes on in the rest of the budget. So the
// linearised point follows the stream every call, and the exact model
// catches up every few.

#include <cstdint>

#include "cdcr/model/ik/solve_flow.hpp"
#include "cdcr/model/work_costs.hpp"

namespace cdcr::model::ik {

class Stream {
 public:
  // Streamed steps let go on rows of an earlier point before the rows are
  // renewed.
  static constexpr int kMaxStaleRowSteps = 4;

  bool rows_overdue() const { return stale_row_steps_ >= kMaxStaleRowSteps; }
  void rows_renewed() { stale_row_steps_ = 0; }

  // The step within `budget`; returns the units spent. New rows
  // (renew_rows()) when the slice also holds the step (and an outer step
  // waiting for its turn: a cycle whose new rows crowded out the step sent
  // the last target's point again), or when the old ones have served long
  // enough (that cycle's step then waits a cycle). An outer step waiting for
  // its turn goes first when the slice cannot hold both: the stream's steps
  // must not starve the evaluations.
  template <typename RenewRows, typename TakeStep>
  std::uint32_t step(std::uint32_t budget, const IkWorkCosts& costs, const SolveFlow& flow, RenewRows&& renew_rows,
                     TakeStep&& take_step) {
    std::uint32_t spent = 0;
    const std::uint32_t waiting = flow.phase() == Phase::outer_step ? costs.outer_step : 0;
    const bool renew = !flow.rows_current() && (budget >= costs.nominal_jacobian + costs.nominal_step + waiting ||
                                                stale_row_steps_ >= kMaxStaleRowSteps);
    if (renew && budget >= costs.nominal_jacobian) {
      spent += costs.nominal_jacobian;
      renew_rows();
    }
    if (budget - spent < costs.nominal_step + waiting) return spent;
    spent += costs.nominal_step;
    take_step();
    if (!flow.rows_current()) ++stale_row_steps_;
    return spent;
  }

 private:
  // Streamed steps taken on rows of an earlier point.
  int stale_row_steps_ = 0;
};

}  // namespace cdcr::model::ik
