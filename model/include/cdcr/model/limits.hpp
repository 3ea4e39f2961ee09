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

}  // namespace cdcr::model
