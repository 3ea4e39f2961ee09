#pragma once
// When a start has stalled, and where the next one begins (ik_solver.hpp):
// a start stalls when the exact residual stops decreasing clearly over
// outer iterations; it is then restarted from the next start in a fixed
// list, up to IkSolverOptions::max_restarts.

#include <algorithm>

#include "cdcr/model/chain.hpp"
#include "cdcr/model/geometry.hpp"
#include "cdcr/model/ik/options.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model::ik {

template <typename S, int Max>
class Restarts {
 public:
  using Joints = JointVector<S, Max>;

  void reset() {
    restarts_ = 0;
    stalled_outer_ = 0;
  }
  int count() const { return restarts_; }

  // An outer iteration's squared residual against the last one's (when
  // there is a last one).
  void record(bool has_previous, S cost, S previous_cost) {
    if (has_previous && !(cost < S(0.9) * previous_cost)) {
      ++stalled_outer_;
    } else {
      stalled_outer_ = 0;
    }
  }

  // Two stalled outer iterations end a start; within 3 tolerances of the
  // target it takes a third, since there the residual wanders at the float
  // correction's scatter (tools/bench/README.md, IK section).
  bool stalled(S position_error, const IkSolverOptions<S>& options) const {
    const bool wandering_at_tolerance = position_error <= S(3) * options.position_tolerance_mm;
    return stalled_outer_ >= (wandering_at_tolerance ? 3 : 2);
  }

  // Near the tolerance a stall is the arithmetic's floor, not a bad start.
  static bool at_floor(S position_error, const IkSolverOptions<S>& options) {
    return position_error <= S(20) * options.position_tolerance_mm;
  }

  // The next start's bends, unless the bound is reached: the straight robot
  // with a slight bend, then bends turned a quarter and a half turn.
  bool next_start(const IkSolverOptions<S>& options, const RobotGeometry<S, Max>& geometry, Joints& bend) {
    if (restarts_ >= options.max_restarts) return false;
    ++restarts_;
    Joints joints(2 * geometry.segment_count);
    static constexpr S kPhase[] = {S(0), S(1.5707963), S(3.1415927), S(-1.5707963)};
    for (int i = 0; i < geometry.segment_count; ++i) {
      joints[2 * i] = kPhase[(restarts_ + i) % 4];
      joints[2 * i + 1] = std::min(S(0.1) * S(restarts_), geometry.segments[i].theta_max_rad);
    }
    stalled_outer_ = 0;
    bend = bend_from_joints(joints);
    return true;
  }

 private:
  int restarts_ = 0;
  int stalled_outer_ = 0;
};

}  // namespace cdcr::model::ik
