#pragma once
// What a solve is asked for and within which bounds: the target's kind, the
// solver's outcome, its options and the preference among a redundant
// robot's solutions (ik_solver.hpp).

#include <cstdint>
#include <type_traits>

#include "cdcr/model/types.hpp"

namespace cdcr::model {

enum class IkTargetKind : std::uint8_t { position, pose };

enum class IkSolveState : std::uint8_t {
  idle,           // no target
  running,        // work left; call run() again
  converged,      // tolerance reached on the compensated model
  not_converged,  // a bound was reached first; best() holds the best point found
  failed,         // the model refused an input (see status())
};

template <typename S>
struct IkSolverOptions {
  S position_tolerance_mm = std::is_same_v<S, float> ? S(2e-3) : S(1e-9);
  S orientation_tolerance_rad = std::is_same_v<S, float> ? S(2e-5) : S(1e-11);
  // Converts the orientation residual to millimetres so that one step weighs
  // both parts; zero means the mean backbone length (1 rad of bend moves a
  // segment tip by about that much).
  S orientation_weight_mm_per_rad = S(0);
  // LM damping, relative to the normal matrix's mean diagonal. Near the
  // target (within keep_damping_within_mm), the damping reached carries
  // over from one outer iteration to the next, down to min_damping: a pose
  // target's weakly actuated direction (the twist about the backbone that
  // only combined bends give) converges at the rate the damping allows, and
  // a damping reset every outer iteration held it to a crawl. Farther out,
  // each outer iteration starts from initial_damping again, which keeps
  // full-range solves from overshooting into other basins.
  S initial_damping = S(1e-4);
  S min_damping = std::is_same_v<S, float> ? S(1e-6) : S(1e-12);
  S keep_damping_within_mm = S(1);
  // Correction evaluations per solve (each is one outer iteration).
  int max_corrections = 40;
  // Nominal LM iterations per solve, over all outer iterations and restarts.
  int max_iterations = 400;
  // Nominal LM iterations between two correction evaluations.
  int max_inner_iterations = 12;
  // Starts after the first one, when a start stalls above the arithmetic's
  // floor (20 position tolerances), or when no step helps at all further
  // than restart_above_mm from the target.
  int max_restarts = 3;
  S restart_above_mm = S(1);
  // Learn the correction's slope from the evaluations (Broyden).
  bool secant_updates = true;
  // Evaluate the correction's gradient (when it offers one) at a cold start
  // and after an outer iteration whose squared residual fell by less than
  // this factor. Zero: never (the fixed point with secant updates only).
  S gradient_refresh_ratio = S(0.05);
};

// Where the solver prefers its solutions among the many of a redundant
// robot (four segments: eight joint variables for a six-variable pose). Each
// LM step gets a second part in the null space of the pose task: a fraction
// `gain` of the way from the current bends towards `centre`, weighted per
// coordinate by `weight` (largest 1), with every segment beyond `limit_margin`
// of its theta limit pulled back inside it, projected so that, to first
// order, it leaves the residual alone. The runtime puts the centre in the
// middle of the range the model was fitted on (firmware/ik_settings.hpp):
// near it the correction interpolates and its variance is low, and the theta
// limit is far. The LM step is the minimum-norm one, so the solution stays
// near the start (a streamed target's last solution) unless the preference
// moves it, and then only continuously: no jumps between branches along a
// path.
template <typename S, int Max>
struct IkPreference {
  JointVector<S, Max> centre;
  JointVector<S, Max> weight;
  S gain = S(0);  // 0: no preference
  S limit_margin = S(0.1);
};

}  // namespace cdcr::model
