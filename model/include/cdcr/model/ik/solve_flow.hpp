#pragma once
// Where a solve stands between two steps (ik_solver.hpp): its phase and
// what it knows, each as a small state, and the one function that moves
// between them. Every step of the solver reports what happened (an Event)
// and reads the states back; none of them sets a state itself.
//
// States (initial first):
//   Phase          evaluate | outer_step | inner
//                  the correction at a point is being evaluated; the outer
//                  step (convergence test, slope, set-up of the linearised
//                  solve) waits for its turn; the linearised LM solve runs
//   Linearisation  none | in_use
//                  an evaluated correction (and slope) is there to solve on
//   Evaluated      mean | mean_and_gradient
//                  what the last finished evaluation brought
//   Slope          unknown | known
//   GradientPlan   as_needed | with_next_evaluation | after_first_outer_step
//                  whether the next evaluation brings the gradient: only
//                  while the slope is unknown, always, or (start_near())
//                  decided at the first outer step, which then asks for it
//   History        none | restarted | iterated
//                  outer steps since the target was set: none; some, but
//                  none since the last restart (the damping carries on, the
//                  last point does not count); the last one is there
//   WarmStart      none | available
//                  a best point with its correction, for the next target
//   Rows           none | of_earlier_point | current
//                  the LM rows (Jacobian) for this target kind, and whether
//                  they are the current point's
//   StreamStep     none | due
//                  a streamed target's step comes first in the next run()
//   StreamedPoint  no | yes
//                  streamed steps have moved the linearised point since the
//                  last evaluation began
//   PreferenceStep included | left_out
//                  the next LM step has the preference's part, or not
//                  (after a step it spoilt)
//
// Events and what they move (every other state stays):
//   configured            Linearisation none, Slope unknown, WarmStart none,
//                         Rows none
//   target_set            GradientPlan as_needed, History none, StreamStep
//                         none, StreamedPoint no, PreferenceStep included
//   cold_start            Linearisation none, Rows none
//   warm_start            Evaluated mean, Phase outer_step
//   near_start            GradientPlan after_first_outer_step
//   kind_changed          Rows none
//   streamed_target       StreamStep due
//   stream_step_taken_up  StreamStep none
//   stream_moved_point    StreamedPoint yes
//   outer_begun           StreamedPoint no
//   evaluation_begun      Phase evaluate
//   evaluated_mean        Evaluated mean, Phase outer_step
//   evaluated_with_gradient  Evaluated mean_and_gradient, Phase outer_step
//   slope_set             Slope known
//   slope_lost            Slope unknown
//   best_kept             WarmStart available
//   restarted             History iterated -> restarted, Slope unknown
//   outer_done            GradientPlan as_needed, History iterated,
//                         Linearisation in_use, Rows current ->
//                         of_earlier_point, Phase inner
//   outer_done_gradient_next  as outer_done, GradientPlan
//                         with_next_evaluation
//   rows_updated          Rows current
//   step_accepted         Rows current -> of_earlier_point, PreferenceStep
//                         included
//   preferred_step_spoilt PreferenceStep left_out
//   step_rejected         PreferenceStep included

#include <cstdint>

namespace cdcr::model::ik {

enum class Phase : std::uint8_t { evaluate, outer_step, inner };

enum class Event : std::uint8_t {
  configured,
  target_set,
  cold_start,
  warm_start,
  near_start,
  kind_changed,
  streamed_target,
  stream_step_taken_up,
  stream_moved_point,
  outer_begun,
  evaluation_begun,
  evaluated_mean,
  evaluated_with_gradient,
  slope_set,
  slope_lost,
  best_kept,
  restarted,
  outer_done,
  outer_done_gradient_next,
  rows_updated,
  step_accepted,
  preferred_step_spoilt,
  step_rejected,
};

class SolveFlow {
 public:
  enum class Linearisation : std::uint8_t { none, in_use };
  enum class Evaluated : std::uint8_t { mean, mean_and_gradient };
  enum class Slope : std::uint8_t { unknown, known };
  enum class GradientPlan : std::uint8_t { as_needed, with_next_evaluation, after_first_outer_step };
  enum class History : std::uint8_t { none, restarted, iterated };
  enum class WarmStart : std::uint8_t { none, available };
  enum class Rows : std::uint8_t { none, of_earlier_point, current };
  enum class StreamStep : std::uint8_t { none, due };
  enum class StreamedPoint : std::uint8_t { no, yes };
  enum class PreferenceStep : std::uint8_t { included, left_out };

  // The transition table above, and nothing else sets a state.
  void on(Event event) {
    switch (event) {
      case Event::configured:
        linearisation_ = Linearisation::none;
        slope_ = Slope::unknown;
        warm_start_ = WarmStart::none;
        rows_ = Rows::none;
        break;
      case Event::target_set:
        gradient_plan_ = GradientPlan::as_needed;
        history_ = History::none;
        stream_step_ = StreamStep::none;
        streamed_point_ = StreamedPoint::no;
        preference_step_ = PreferenceStep::included;
        break;
      case Event::cold_start:
        linearisation_ = Linearisation::none;
        rows_ = Rows::none;
        break;
      case Event::warm_start:
        evaluated_ = Evaluated::mean;
        phase_ = Phase::outer_step;
        break;
      case Event::near_start:
        gradient_plan_ = GradientPlan::after_first_outer_step;
        break;
      case Event::kind_changed:
        rows_ = Rows::none;
        break;
      case Event::streamed_target:
        stream_step_ = StreamStep::due;
        break;
      case Event::stream_step_taken_up:
        stream_step_ = StreamStep::none;
        break;
      case Event::stream_moved_point:
        streamed_point_ = StreamedPoint::yes;
        break;
      case Event::outer_begun:
        streamed_point_ = StreamedPoint::no;
        break;
      case Event::evaluation_begun:
        phase_ = Phase::evaluate;
        break;
      case Event::evaluated_mean:
        evaluated_ = Evaluated::mean;
        phase_ = Phase::outer_step;
        break;
      case Event::evaluated_with_gradient:
        evaluated_ = Evaluated::mean_and_gradient;
        phase_ = Phase::outer_step;
        break;
      case Event::slope_set:
        slope_ = Slope::known;
        break;
      case Event::slope_lost:
        slope_ = Slope::unknown;
        break;
      case Event::best_kept:
        warm_start_ = WarmStart::available;
        break;
      case Event::restarted:
        if (history_ == History::iterated) history_ = History::restarted;
        slope_ = Slope::unknown;
        break;
      case Event::outer_done:
      case Event::outer_done_gradient_next:
        gradient_plan_ =
            event == Event::outer_done_gradient_next ? GradientPlan::with_next_evaluation : GradientPlan::as_needed;
        history_ = History::iterated;
        linearisation_ = Linearisation::in_use;
        if (rows_ == Rows::current) rows_ = Rows::of_earlier_point;
        phase_ = Phase::inner;
        break;
      case Event::rows_updated:
        rows_ = Rows::current;
        break;
      case Event::step_accepted:
        if (rows_ == Rows::current) rows_ = Rows::of_earlier_point;
        preference_step_ = PreferenceStep::included;
        break;
      case Event::preferred_step_spoilt:
        preference_step_ = PreferenceStep::left_out;
        break;
      case Event::step_rejected:
        preference_step_ = PreferenceStep::included;
        break;
    }
  }

  Phase phase() const { return phase_; }
  bool linearised() const { return linearisation_ == Linearisation::in_use; }
  bool evaluated_with_gradient() const { return evaluated_ == Evaluated::mean_and_gradient; }
  bool slope_known() const { return slope_ == Slope::known; }
  bool gradient_with_next_evaluation() const { return gradient_plan_ == GradientPlan::with_next_evaluation; }
  bool gradient_after_first_outer_step() const { return gradient_plan_ == GradientPlan::after_first_outer_step; }
  // The last outer point of this start, for the secant and the stall test.
  bool has_previous() const { return history_ == History::iterated; }
  // The damping reached carries on (an outer step was made on this target).
  bool has_damping() const { return history_ != History::none; }
  bool has_warm_start() const { return warm_start_ == WarmStart::available; }
  bool rows_valid() const { return rows_ != Rows::none; }
  bool rows_current() const { return rows_ == Rows::current; }
  bool stream_step_due() const { return stream_step_ == StreamStep::due; }
  bool streamed_point() const { return streamed_point_ == StreamedPoint::yes; }
  bool preference_included() const { return preference_step_ == PreferenceStep::included; }

 private:
  Phase phase_ = Phase::evaluate;
  Linearisation linearisation_ = Linearisation::none;
  Evaluated evaluated_ = Evaluated::mean;
  Slope slope_ = Slope::unknown;
  GradientPlan gradient_plan_ = GradientPlan::as_needed;
  History history_ = History::none;
  WarmStart warm_start_ = WarmStart::none;
  Rows rows_ = Rows::none;
  StreamStep stream_step_ = StreamStep::none;
  StreamedPoint streamed_point_ = StreamedPoint::no;
  PreferenceStep preference_step_ = PreferenceStep::included;
};

}  // namespace cdcr::model::ik
