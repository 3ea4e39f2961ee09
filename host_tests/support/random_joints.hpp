#pragma once
// Joint vectors drawn at random for tests that need configurations of a
// robot: per segment alpha, then theta, from the caller's generator and
// ranges, so the same seed gives the same robot poses in every test.

#include <random>

#include "cdcr/model/types.hpp"

namespace cdcr::test_support {

template <typename Rng>
model::JointVector<double> random_joints(int segment_count, Rng& rng, std::uniform_real_distribution<double>& alpha_rad,
                                         std::uniform_real_distribution<double>& theta_rad) {
  model::JointVector<double> joints(2 * segment_count);
  for (int s = 0; s < segment_count; ++s) {
    joints[2 * s] = alpha_rad(rng);
    joints[2 * s + 1] = theta_rad(rng);
  }
  return joints;
}

}  // namespace cdcr::test_support
