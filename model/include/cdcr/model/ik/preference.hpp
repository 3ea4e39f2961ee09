#pragma once
// The preference's part of an LM step (IkPreference, ik/options.hpp): a
// pull towards the preferred bends, projected into the null space of the
// pose task.

#include "cdcr/model/geometry.hpp"
#include "cdcr/model/ik/options.hpp"
#include "cdcr/model/ik/solve_flow.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model::ik {

template <typename S, int Max>
class Preference {
 public:
  using Joints = JointVector<S, Max>;

  // Off (gain zero) unless it fits the geometry and is finite.
  void set(const IkPreference<S, Max>& preference, const RobotGeometry<S, Max>* geometry) {
    preference_ = preference;
    if (geometry == nullptr || !(preference_.gain > S(0)) || preference_.centre.size() != 2 * geometry->segment_count ||
        preference_.weight.size() != 2 * geometry->segment_count || !preference_.centre.allFinite() ||
        !preference_.weight.allFinite()) {
      preference_.gain = S(0);
    }
  }
  void clear() { preference_ = IkPreference<S, Max>{}; }

  // Within 20 tolerances of the target (where a stall counts as the
  // arithmetic's floor) the steps are the pose task's alone: the
  // preference's drift, however small, spoils the secant slope the last few
  // um need (figures: tools/bench/README.md, IK section).
  bool applies(bool may_prefer, const SolveFlow& flow, S position_error, const IkSolverOptions<S>& options) const {
    return may_prefer && flow.preference_included() && preference_.gain > S(0) &&
           position_error > S(20) * options.position_tolerance_mm;
  }

  // Adds to the pose task's step J^T (J J^T + damping)^-1 r that of the
  // pull z on the same factor: z less what the pose task sees of it,
  // z - J^T (J J^T + damping)^-1 J z, on the reduced coordinates `used`
  // (two per free segment, one along the limit circle per active one).
  template <int Rows, typename Used, typename Factor, typename Step>
  void add_to_step(Step& step, const Used& used, const Factor& factor, int columns, const Joints& bend,
                   const bool* active, const Vec2<S>* tangent, const RobotGeometry<S, Max>& geometry) const {
    Step z(columns);
    columns = 0;
    for (int i = 0; i < geometry.segment_count; ++i) {
      const Vec2<S> b = bend.template segment<2>(2 * i);
      Vec2<S> pull = preference_.weight.template segment<2>(2 * i).cwiseProduct(
          preference_.centre.template segment<2>(2 * i) - b);
      const S theta = b.norm();
      const S keep_within = (S(1) - preference_.limit_margin) * geometry.segments[i].theta_max_rad;
      if (theta > keep_within) pull -= ((theta - keep_within) / theta) * b;
      pull *= preference_.gain;
      if (active[i]) {
        z[columns++] = tangent[i].dot(pull);
      } else {
        z.template segment<2>(columns) = pull;
        columns += 2;
      }
    }
    const Eigen::Matrix<S, Rows, 1> seen = used.lazyProduct(z);
    Step null_step = z - used.transpose().lazyProduct(factor.solve(seen));
    // Never longer than the pose task's own step: the preference's leak
    // through the damping then stays a fraction of the step, and the last
    // steps before a solution are left alone (tools/bench/README.md, IK
    // section).
    const S longest = step.norm();
    const S length = null_step.norm();
    if (length > longest) null_step *= longest / length;
    step += null_step;
  }

 private:
  IkPreference<S, Max> preference_{};
};

}  // namespace cdcr::model::ik
