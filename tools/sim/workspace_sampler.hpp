#pragma once
// Random configurations as in the paper's experiment (Section V-B): joint
// variables drawn at random, alpha uniform in [-pi, pi] and theta uniform in
// [0, theta_max], and the cable lengths commanded through the NOMINAL inverse
// (eq. 2), exactly as a user of the nominal model would command the robot.
// theta is uniform in value, not in area, so straight-ish segments are
// sampled more densely than a uniform disk of bend vectors would.

#include <cstdint>

#include <cdcr/model/geometry.hpp>
#include <cdcr/model/types.hpp>

#include "sim/random_stream.hpp"

namespace cdcr::sim {

struct WorkspaceSample {
  model::JointVector<double> joints;    // [alpha_1, theta_1, ...] as sampled
  model::CableVector<double> cables_mm;  // nominal inverse of the joints
};

class WorkspaceSampler {
 public:
  // theta_max_rad must lie in (0, theta_max] of every nominal segment
  // (std::invalid_argument otherwise).
  WorkspaceSampler(const model::RobotGeometry<double>& nominal, double theta_max_rad, std::uint64_t seed);

  WorkspaceSample next();

 private:
  model::RobotGeometry<double> nominal_;
  double theta_max_rad_;
  RandomStream random_;
};

}  // namespace cdcr::sim
