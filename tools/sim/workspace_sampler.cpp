#include "sim/workspace_sampler.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <cdcr/model/chain.hpp>
#include <cdcr/model/units.hpp>

namespace cdcr::sim {

WorkspaceSampler::WorkspaceSampler(const model::RobotGeometry<double>& nominal, double theta_max_rad,
                                   std::uint64_t seed)
    : nominal_(nominal), theta_max_rad_(theta_max_rad), random_(seed, StreamId::workspace) {
  if (const model::Status status = nominal.validate(); status != model::Status::ok) {
    throw std::invalid_argument(std::string("invalid nominal geometry: ") + model::to_string(status));
  }
  if (!std::isfinite(theta_max_rad) || !(theta_max_rad > 0.0)) {
    throw std::invalid_argument("workspace theta_max must be positive");
  }
  for (int i = 0; i < nominal.segment_count; ++i) {
    if (theta_max_rad > nominal.segments[i].theta_max_rad) {
      throw std::invalid_argument("workspace theta_max exceeds the theta_max of segment " + std::to_string(i + 1));
    }
  }
}

WorkspaceSample WorkspaceSampler::next() {
  const int n = nominal_.segment_count;
  WorkspaceSample sample;
  sample.joints.resize(2 * n);
  for (int i = 0; i < n; ++i) {
    sample.joints[2 * i] = random_.uniform(-model::kPi, model::kPi);
    sample.joints[2 * i + 1] = random_.uniform(0.0, theta_max_rad_);
  }
  if (const model::Status status = model::cables_from_joints(sample.joints, nominal_, sample.cables_mm);
      status != model::Status::ok) {
    // Only a geometry whose cables run out of length (r theta > L) gets here.
    throw std::invalid_argument(std::string("nominal inverse kinematics failed: ") + model::to_string(status));
  }
  return sample;
}

}  // namespace cdcr::sim
