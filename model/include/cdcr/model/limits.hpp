#pragma once
// Compile-time capacities of the model library. A runtime robot may use fewer
// segments; storage is always sized for these maxima so nothing is allocated.

namespace cdcr::model {

inline constexpr int kMaxSegments = 8;

}  // namespace cdcr::model
