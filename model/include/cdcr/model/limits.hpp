#pragma once
// Compile-time capacities of the model library. A runtime robot may use fewer
// segments; storage is always sized for these maxima so nothing is allocated.

namespace cdcr::model {

inline constexpr int kMaxSegments = 8;

// Largest GP training set a model image may hold (the paper uses up to 700).
inline constexpr unsigned kMaxTrainingPoints = 1024;

// Largest predictive-variance factor an image may hold (its points, R): the
// variance costs R kernel values and R (R + 1) multiply-adds per query.
inline constexpr unsigned kMaxVarianceRank = 64;

// Inputs a model may take after the joint encoding: the tip payload (kg).
inline constexpr int kMaxExtraInputs = 1;

// GP inputs of a robot of `segments` segments: a bend pair per segment, then
// the extra inputs. A model that also takes its cables' residuals must fit
// the same count (the paper's four segments do: 4 x 4 inputs).
constexpr int max_model_inputs(int segments) { return 2 * segments + kMaxExtraInputs; }

// What a segment's cables say beyond the bend, per segment: the cable
// fit's common mode and pair imbalance (cable_fit.hpp; the imbalance is an
// input only with four cables, input_encoding.hpp). A model that takes
// them, and the cables' history (one input per cable), must fit the same
// count too (one segment: 2 + 2 + 4 inputs; two: 16).
inline constexpr int kCableResidualsPerSegment = 2;
inline constexpr int kMaxInputs = max_model_inputs(kMaxSegments);

// Cables of a segment: three (at 120 degrees, the fewest that read a bend
// in any direction) or four (the paper's, at 90 degrees; the most a
// CABLE_FEEDBACK frame carries).
inline constexpr int kMinCablesPerSegment = 3;
inline constexpr int kMaxCablesPerSegment = 4;

// Cables of the largest robot.
inline constexpr int kMaxCables = kMaxCablesPerSegment * kMaxSegments;

// Play operators per cable a hysteresis model may hold (hysteresis.hpp).
inline constexpr int kMaxHysteresisOperators = 4;

// Widest play operator a hysteresis model may hold (mm): the homing move
// must take every cable twice as far to make the state known.
inline constexpr double kMaxHysteresisWidthMm = 2.0;

// A payload compliance's softening s must keep 1 + s |b| positive for
// bends up to this (a quarter turn, beyond any segment's design limit
// here): the image parser and the trainer's ranking both require it.
inline constexpr double kComplianceLargestBendRad = 1.5707963267948966;

}  // namespace cdcr::model
