#pragma once
// Joint vectors drawn at random for tests that need configurations of a
// robot: per segment alpha, then theta, from the caller's generator and
// ranges, so the same seed gives the same robot poses in every test.

#include <cmath>
#include <random>

#include "cdcr/model/chain.hpp"
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

// One step of a random walk through joint space, for motion sequences: every
// joint moves by step(rng), each theta folded back to >= 0 (a bend that
// crosses straight continues as the opposite alpha's); `cables` are those of
// the new joints through `geometry`.
template <typename Rng>
model::Status random_walk_step(model::JointVector<double>& joints, Rng& rng,
                               std::uniform_real_distribution<double>& step,
                               const model::RobotGeometry<double>& geometry, model::CableVector<double>& cables) {
  for (int k = 0; k < joints.size(); ++k) joints[k] += step(rng);
  for (int k = 1; k < joints.size(); k += 2) joints[k] = std::abs(joints[k]);
  return model::cables_from_joints(joints, geometry, cables);
}

}  // namespace cdcr::test_support
