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
// the extra inputs.
constexpr int max_model_inputs(int segments) { return 2 * segments + kMaxExtraInputs; }
inline constexpr int kMaxInputs = max_model_inputs(kMaxSegments);

}  // namespace cdcr::model
