#pragma once
// The simulator's tests bound a mean pose error from both sides, in position
// and in orientation: a floor or an initial error must be of the right size,
// neither vanishing nor exploding.

#include <gtest/gtest.h>

#include "sim/data_collection.hpp"

namespace cdcr::sim::test_types {

// Each figure strictly between its bounds.
inline void expect_mean_error_between(const MeanPoseError& error, double min_mm, double max_mm, double min_deg,
                                      double max_deg) {
  EXPECT_GT(error.position_mm, min_mm);
  EXPECT_LT(error.position_mm, max_mm);
  EXPECT_GT(error.orientation_deg, min_deg);
  EXPECT_LT(error.orientation_deg, max_deg);
}

}  // namespace cdcr::sim::test_types
