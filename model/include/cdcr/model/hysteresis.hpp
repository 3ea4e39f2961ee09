#pragma once
// Friction hysteresis of the cables: the length that bends a segment (the
// effective length) lags the length the drive commands, by an amount that
// depends on which way the cable last moved. Rate-independent, so only the
// path of the commanded length matters, not its speed.
//
// Per cable c, a weighted sum of K play (backlash) operators (a
// Prandtl-Ishlinskii operator with unit gain far from a reversal):
//
//   lag_k      = clamp(lag_k + dx, -r_k, r_k)    dx: the commanded length's change
//   effective  = commanded - sum_k w_k lag_k     w_k in [0, 1], sum_k w_k <= 1
//
// The state is the lag of every operator (mm), not its output: a lag does not
// change with where the cable is, so the state after the homing move is a
// constant of the robot. After a long move towards longer cables lag_k = r_k:
// the effective length trails the commanded one by sum_k w_k r_k. Inside a
// reversal the effective length moves with slope 1 - sum over unsaturated
// operators of w_k; with sum_k w_k = 1 that is a dead band of 2 r_k.
//
// Unknown state. At power-up the lags are unknown. The state keeps, per
// operator, the interval [low, high] the lag must lie in; both ends go
// through the same clamp, which preserves order, so the interval only
// shrinks, and it closes (low == high exactly, in any precision) once the
// cable has moved 2 r_k in one direction. The estimate is the interval's
// midpoint, and its half-width bounds the error of the effective length.
//
// Homing. The homing move (homing_waypoints) takes every cable at least
// kHomingTravelMm in one direction just before the robot reaches home, the
// straight robot, so every lag there is known whatever it was before.
//
// Everything here is templated on the scalar (double in the trainer, float
// on the board), header-only, allocation-free and without exceptions.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <Eigen/Core>

#include "cdcr/model/geometry.hpp"
#include "cdcr/model/limits.hpp"
#include "cdcr/model/segment.hpp"
#include "cdcr/model/status.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model {

// Parameters of the hysteresis of every cable of a robot. Cable c uses
// widths[c][0..operators) and weights[c][0..operators); homing_lag is the
// state the homing move leaves.
template <typename S>
struct HysteresisModel {
  int cables = 0;     // the robot's cables; 0: no hysteresis model
  int operators = 0;  // play operators per cable, 1..kMaxHysteresisOperators
  S widths_mm[kMaxCables][kMaxHysteresisOperators] = {};
  S weights[kMaxCables][kMaxHysteresisOperators] = {};
  S homing_lag_mm[kMaxCables][kMaxHysteresisOperators] = {};

  bool empty() const { return cables == 0; }

  // The largest lag of the effective length behind the commanded one (mm).
  S max_lag_mm(int cable) const {
    S sum = S(0);
    for (int k = 0; k < operators; ++k) sum += weights[cable][k] * widths_mm[cable][k];
    return sum;
  }
};

// Why a hysteresis model is not usable; the image parser reports the same.
enum class HysteresisCheck : std::uint8_t {
  ok = 0,
  bad_counts,         // cables not the robot's, or operators outside 1..capacity
  bad_width,          // a width not finite, negative or above kMaxHysteresisWidthMm
  bad_weight,         // a weight not finite, negative, or a cable's weights summing above 1
  bad_homing_lag,     // a homing lag not finite or outside [-width, width]
};

template <typename S>
HysteresisCheck check_hysteresis(const HysteresisModel<S>& model, int cable_count) {
  if (model.cables != cable_count || model.cables > kMaxCables || model.operators < 1 ||
      model.operators > kMaxHysteresisOperators) {
    return HysteresisCheck::bad_counts;
  }
  for (int c = 0; c < model.cables; ++c) {
    S weight_sum = S(0);
    for (int k = 0; k < model.operators; ++k) {
      const S width = model.widths_mm[c][k];
      const S weight = model.weights[c][k];
      const S lag = model.homing_lag_mm[c][k];
      // Wider operators than the limit would not all close on the homing move.
      if (!std::isfinite(width) || !(width >= S(0)) || !(width <= S(kMaxHysteresisWidthMm))) {
        return HysteresisCheck::bad_width;
      }
      if (!std::isfinite(weight) || !(weight >= S(0))) return HysteresisCheck::bad_weight;
      if (!std::isfinite(lag) || !(std::abs(lag) <= width)) return HysteresisCheck::bad_homing_lag;
      weight_sum += weight;
    }
    // A small allowance for the rounding of weights written in float32.
    if (!(weight_sum <= S(1) + S(8) * std::numeric_limits<S>::epsilon())) return HysteresisCheck::bad_weight;
  }
  return HysteresisCheck::ok;
}

// The lag interval of every operator of every cable, and the commanded
// lengths it belongs to.
template <typename S>
struct HysteresisState {
  int cables = 0;
  int operators = 0;
  bool has_position = false;  // commanded_mm holds the last commanded lengths
  S commanded_mm[kMaxCables] = {};
  S lag_low_mm[kMaxCables][kMaxHysteresisOperators] = {};
  S lag_high_mm[kMaxCables][kMaxHysteresisOperators] = {};

  // True when every lag is known exactly.
  bool known() const {
    for (int c = 0; c < cables; ++c) {
      for (int k = 0; k < operators; ++k) {
        if (lag_low_mm[c][k] != lag_high_mm[c][k]) return false;
      }
    }
    return true;
  }
};

// What both resets share: the model's dimensions, no position yet, and each
// operator's lag interval set to lag_interval(c, k, low, high).
template <typename S, typename LagInterval>
void reset_hysteresis_state(HysteresisState<S>& state, const HysteresisModel<S>& model, LagInterval lag_interval) {
  state.cables = model.cables;
  state.operators = model.operators;
  state.has_position = false;
  for (int c = 0; c < model.cables; ++c) {
    state.commanded_mm[c] = S(0);
    for (int k = 0; k < model.operators; ++k) lag_interval(c, k, state.lag_low_mm[c][k], state.lag_high_mm[c][k]);
  }
}

// Power-up: nothing known; each lag anywhere within its width.
template <typename S>
void reset_unknown(HysteresisState<S>& state, const HysteresisModel<S>& model) {
  reset_hysteresis_state(state, model, [&model](int c, int k, S& low, S& high) {
    low = -model.widths_mm[c][k];
    high = model.widths_mm[c][k];
  });
}

// The robot has just completed the homing move: every lag is the model's
// homing lag. The next commanded lengths (update) set the position.
template <typename S>
void reset_to_homing(HysteresisState<S>& state, const HysteresisModel<S>& model) {
  reset_hysteresis_state(state, model, [&model](int c, int k, S& low, S& high) {
    low = model.homing_lag_mm[c][k];
    high = model.homing_lag_mm[c][k];
  });
}

// Moves every cable to `commanded_mm` (the drives' lengths, one per cable) in
// a straight line: each cable's change is monotone, so one clamp per operator
// is exact. The first call after a reset only records the position.
template <typename S, typename Derived>
void update_hysteresis(HysteresisState<S>& state, const HysteresisModel<S>& model,
                       const Eigen::MatrixBase<Derived>& commanded_mm) {
  for (int c = 0; c < state.cables; ++c) {
    const S x = commanded_mm[c];
    if (state.has_position) {
      const S dx = x - state.commanded_mm[c];
      for (int k = 0; k < state.operators; ++k) {
        const S r = model.widths_mm[c][k];
        state.lag_low_mm[c][k] = std::min(r, std::max(-r, state.lag_low_mm[c][k] + dx));
        state.lag_high_mm[c][k] = std::min(r, std::max(-r, state.lag_high_mm[c][k] + dx));
      }
    }
    state.commanded_mm[c] = x;
  }
  state.has_position = true;
}

// The effective lengths at the state's position, from the lags' midpoints;
// uncertainty_mm (optional) receives, per cable, the largest error that the
// unknown part of the state allows (0 once known).
// CableVector: a resizable Eigen vector (model::CableVector, Eigen::VectorXd).
template <typename S, typename CableVectorType>
void effective_lengths(const HysteresisState<S>& state, const HysteresisModel<S>& model,
                       CableVectorType& effective_mm, CableVectorType* uncertainty_mm = nullptr) {
  effective_mm.resize(state.cables);
  if (uncertainty_mm != nullptr) uncertainty_mm->resize(state.cables);
  for (int c = 0; c < state.cables; ++c) {
    S lag = S(0);
    S spread = S(0);
    for (int k = 0; k < state.operators; ++k) {
      const S w = model.weights[c][k];
      lag += w * S(0.5) * (state.lag_low_mm[c][k] + state.lag_high_mm[c][k]);
      spread += w * S(0.5) * (state.lag_high_mm[c][k] - state.lag_low_mm[c][k]);
    }
    effective_mm[c] = state.commanded_mm[c] - lag;
    if (uncertainty_mm != nullptr) (*uncertainty_mm)[c] = spread;
  }
}

// The history inputs of the GP (input_encoding.hpp): per cable, where it
// last moved, read from the model's last operator as its lag's midpoint over
// its width: +1 after a move of at least twice the width towards a longer
// cable, -1 towards a shorter one, in between inside a reversal, and 0 while
// nothing is known (at power-up, both ends of the interval at +-width). An
// operator of weight 0 keeps this history without moving the effective
// lengths. `out` receives state.cables values.
template <typename S, typename Out>
void history_inputs(const HysteresisState<S>& state, const HysteresisModel<S>& model, Out& out) {
  const int k = state.operators - 1;
  for (int c = 0; c < state.cables; ++c) {
    const S width = model.widths_mm[c][k];
    out[c] = width > S(0) ? S(0.5) * (state.lag_low_mm[c][k] + state.lag_high_mm[c][k]) / width : S(0);
  }
}

// The commanded length of one cable that brings its effective length to
// `effective_target_mm`, moving in a straight line from the state's position
// (the inverse of update_hysteresis and effective_lengths on the
// one-directional move it takes). The effective length is a continuous,
// non-decreasing, piecewise linear function of the commanded one; where it is
// flat (a dead band with sum w_k = 1) and the target is already met, the
// cable stays.
//
// The estimate uses the midpoint of each lag's interval, and update_hysteresis
// clamps both ends of the interval, not the midpoint: while the state is
// unknown an operator acts as two operators of half its weight, one at each
// end, which saturate at different points of the move. With a known lag the
// two ends coincide and it is the operator itself.
template <typename S>
S commanded_for_effective(const HysteresisState<S>& state, const HysteresisModel<S>& model, int cable,
                          S effective_target_mm) {
  constexpr int kEnds = 2 * kMaxHysteresisOperators;
  const S x0 = state.commanded_mm[cable];
  // The effective length now, summed as effective_lengths does.
  S lag = S(0);
  for (int k = 0; k < state.operators; ++k) {
    lag += model.weights[cable][k] * S(0.5) * (state.lag_low_mm[cable][k] + state.lag_high_mm[cable][k]);
  }
  const S need = effective_target_mm - (x0 - lag);
  if (need == S(0)) return x0;
  const S direction = need > S(0) ? S(1) : S(-1);
  // Walk the breakpoints in the direction of travel: the interval end e of
  // operator k saturates after a travel of r_k - direction * e, and from
  // there on adds w_k / 2 to the slope 1 - sum(w / 2) of the unsaturated ends.
  const int ends = 2 * state.operators;
  S travel_to_saturation[kEnds];
  S end_weight[kEnds];
  bool saturated[kEnds];
  S slope = S(1);
  for (int i = 0; i < ends; ++i) {
    const int k = i / 2;
    const S end = (i % 2 == 0) ? state.lag_low_mm[cable][k] : state.lag_high_mm[cable][k];
    end_weight[i] = S(0.5) * model.weights[cable][k];
    travel_to_saturation[i] = std::max(S(0), model.widths_mm[cable][k] - direction * end);
    saturated[i] = travel_to_saturation[i] == S(0);
    if (!saturated[i]) slope -= end_weight[i];
  }
  S travelled = S(0);
  S remaining = std::abs(need);  // effective length still to gain, in the direction of travel
  for (;;) {
    // The next end to saturate.
    int next = -1;
    for (int i = 0; i < ends; ++i) {
      if (!saturated[i] && (next < 0 || travel_to_saturation[i] < travel_to_saturation[next])) next = i;
    }
    const S span = next < 0 ? S(0) : travel_to_saturation[next] - travelled;
    if (next < 0 || (slope > S(0) && slope * span >= remaining)) {
      // slope > 0 here: with every end saturated it is 1.
      return x0 + direction * (travelled + remaining / slope);
    }
    remaining -= slope * span;
    travelled = travel_to_saturation[next];
    saturated[next] = true;
    slope += end_weight[next];
  }
}

// The homing move, in cable space: from wherever the robot is, every segment
// bends by kHomingBendRad towards alpha = 45 degrees (the approach) and
// returns straight (home). On the way home two cables of each segment
// lengthen and two shorten, each by 2 r sin(theta / 2) cos(45 deg)
// (4.7 mm with r = 67 mm): more than twice any width the parser accepts for
// a homing model, so every lag at home is known.
inline constexpr double kHomingBendRad = 0.1;
inline constexpr double kHomingAlphaRad = 0.78539816339744831;

// The approach and home waypoints of the homing move for `geometry`.
template <typename S, int MaxSegments, typename CableVectorType>
Status homing_waypoints(const RobotGeometry<S, MaxSegments>& geometry, CableVectorType& approach_mm,
                        CableVectorType& home_mm) {
  const int n = geometry.segment_count;
  if (n < 1 || n > MaxSegments) return Status::invalid_segment_count;
  approach_mm.resize(geometry.cable_count());
  home_mm.resize(geometry.cable_count());
  for (int i = 0, first = 0; i < n; first += geometry.segments[i].cables.count, ++i) {
    SegmentCables<S> bent, straight;
    const Status bent_status = cables_from_joints(SegmentJoints<S>{S(kHomingAlphaRad), S(kHomingBendRad)},
                                                  geometry.segments[i], bent);
    if (bent_status != Status::ok) return bent_status;
    const Status straight_status = cables_from_joints(SegmentJoints<S>{S(0), S(0)}, geometry.segments[i], straight);
    if (straight_status != Status::ok) return straight_status;
    approach_mm.segment(first, bent.size()) = bent;
    home_mm.segment(first, straight.size()) = straight;
  }
  return Status::ok;
}

// The shortest distance any cable travels on the way home: the homing move
// leaves every lag known when it is at least twice the largest width.
template <typename DerivedA, typename DerivedB>
typename DerivedA::Scalar homing_travel_mm(const Eigen::MatrixBase<DerivedA>& approach_mm,
                                           const Eigen::MatrixBase<DerivedB>& home_mm) {
  return (home_mm - approach_mm).cwiseAbs().minCoeff();
}

// Fills model.homing_lag_mm: the operators run over approach -> home from an
// unknown state; with widths below half the homing travel the interval
// closes and the midpoint is the lag itself.
template <typename S, typename DerivedA, typename DerivedB>
void compute_homing_lags(HysteresisModel<S>& model, const Eigen::MatrixBase<DerivedA>& approach_mm,
                         const Eigen::MatrixBase<DerivedB>& home_mm) {
  HysteresisState<S> state;
  reset_unknown(state, model);
  update_hysteresis(state, model, approach_mm);
  update_hysteresis(state, model, home_mm);
  for (int c = 0; c < model.cables; ++c) {
    for (int k = 0; k < model.operators; ++k) {
      model.homing_lag_mm[c][k] = S(0.5) * (state.lag_low_mm[c][k] + state.lag_high_mm[c][k]);
    }
  }
}

// A session starts after the homing move: the lags are the homing lags and
// the cables are at home, from where the robot moves to the session's first
// row in a straight line (the caller's next update_hysteresis).
template <typename S, int MaxSegments>
Status start_at_home(HysteresisState<S>& state, const HysteresisModel<S>& model,
                     const RobotGeometry<S, MaxSegments>& geometry) {
  CableVector<S, MaxSegments> approach_mm, home_mm;
  const Status status = homing_waypoints(geometry, approach_mm, home_mm);
  if (status != Status::ok) return status;
  reset_to_homing(state, model);
  update_hysteresis(state, model, home_mm);
  return Status::ok;
}

}  // namespace cdcr::model
