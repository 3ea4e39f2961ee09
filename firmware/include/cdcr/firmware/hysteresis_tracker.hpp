#pragma once
// The cables' hysteresis on the board (model/hysteresis.hpp), for an image
// with a hysteresis block: the state of every cable's play operators, kept
// across cycles in the runtime's static memory and moved by the drives'
// lengths of every complete cable set, and the effective lengths the pose is
// estimated on. Without a block every call leaves the lengths as they are.
//
// At power-up the state is unknown: each lag anywhere within its width. It
// becomes known once every cable has travelled twice its widest operator in
// one direction, or at once with a HOMING frame (the robot has just ended
// the homing move: model::start_at_home). While it is unknown the effective
// lengths carry an error of up to +-u per cable (model::effective_lengths).
// A model with the history inputs (input_encoding.hpp) reads where each
// cable last moved from the block's last operator: 0 while unknown, the
// correction's own value for "nothing known".
//
// A segment bends with the differences of opposite cables (l3 - l1,
// l2 - l4), whose errors are then bounded by u_1 + u_3 and u_2 + u_4; each
// is given the largest variance its bound allows, (u_a + u_b)^2: a lag that
// is unknown is mostly at one end of its interval after a move, not spread
// over it, and opposite cables move in opposite directions, so their errors
// add (a uniform, independent error per cable, u^2 / 3 each, covered about
// 60 % of the rows while the state was unknown). It reaches the tip through
// the nominal kinematics' sensitivity to the bend, and its
// covariance is added to the GP's before the r95 radii are taken
// (model::gaussian_radius_95), so the radii widen while the state is unknown
// and are the GP's own, unchanged, once it is known.

#include "cdcr/firmware/capacity.hpp"
#include "cdcr/firmware/kinematics.hpp"
#include "cdcr/model/hysteresis.hpp"

namespace cdcr::firmware {

class HysteresisTracker {
 public:
  // At init, for the model just bound: its image's block, if it is
  // compensated and has one; the state unknown.
  void bind(const RobotModel& model);
  bool active() const { return active_; }
  // Known: always without a block.
  bool known() const { return known_; }

  // The drives' lengths of a complete cable set: moves the state (from the
  // previous set in a straight line) and returns the lengths to estimate the
  // pose on, the effective ones; without a block, or for lengths that are not
  // finite (the kinematics refuses them), `commanded_mm` itself. A segment
  // cannot bend beyond its limit: where the estimated lags would put it
  // there (at the edge of the workspace), its effective cable differences
  // are scaled back to the limit.
  const Cables& track(const Cables& commanded_mm);
  // The robot has just completed the homing move and is at home.
  void homed(const Geometry& geometry);

  // Where each cable last moved (model::history_inputs), held by a
  // correction with the history inputs for the evaluations that follow (the
  // forward path's and IK's); a correction without them, or a tracker
  // without a block, leaves it as it is.
  void hold_history(Correction& correction) const;

  // IK's setpoints: the commanded lengths that bring each cable's effective
  // length to `cables_mm` (in place), moving in a straight line from the
  // latest lengths the drives reported (model::commanded_for_effective);
  // without a block, or before any lengths, unchanged.
  void commanded_for(Cables& cables_mm) const;

  // A pose variance begins on `estimate`: keeps the tip covariance the
  // unknown state adds there (none once known).
  void begin_variance(const RobotModel& model, const PoseEstimate& estimate);
  // The radii of that variance, widened by the covariance kept.
  void widen(const RobotModel& model, model::PoseUncertainty<Scalar>& radii) const;

  const model::HysteresisModel<Scalar>& hysteresis_model() const { return model_; }
  const model::HysteresisState<Scalar>& state() const { return state_; }
  // Per cable, the largest error of the latest effective length (mm).
  const Cables& uncertainty_mm() const { return uncertainty_mm_; }

 private:
  bool active_ = false;
  bool known_ = true;
  model::HysteresisModel<Scalar> model_;
  model::HysteresisState<Scalar> state_;
  Geometry geometry_{};
  Scalar chord_limit_mm_[kMaxSegments] = {};  // per segment, the largest chord |D| (segment.hpp)
  // A model that takes the cables' residuals reads effective lengths
  // beyond the bend limit, as the trainer gave them; only others need them
  // pulled within it.
  bool within_limit_ = true;
  Cables effective_mm_;
  Cables uncertainty_mm_;
  // The covariance added at the pose of the variance in progress: position
  // (mm^2) and orientation (rad^2), each xx, yy, zz, xy, xz, yz; with the
  // GP's covariance at that pose's tip.
  bool widening_ = false;
  Scalar position_covariance_[6] = {};
  Scalar orientation_covariance_[6] = {};
  model::Vec3<Scalar> tip_mm_ = model::Vec3<Scalar>::Zero();
};

// What the tracker costs a cycle (capacity.hpp); 0 without a block.
inline std::uint32_t hysteresis_units(const HysteresisTracker& tracker) {
  const model::HysteresisModel<Scalar>& model = tracker.hysteresis_model();
  if (!tracker.active()) return 0;
  return kHysteresisUnitsPerOperator * static_cast<std::uint32_t>(model.cables * model.operators) +
         kHysteresisWideningUnits;
}

}  // namespace cdcr::firmware
