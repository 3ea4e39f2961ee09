#pragma once
// The paper's data collection (Section V-B) on the simulated robot: random
// workspace configurations, each commanded once and measured once, with the
// initial error of the nominal model and the simulator's noise floor. With
// the payload enabled (SimulatorConfig::payload), each sample also carries a
// payload drawn from its own stream.

#include <vector>

#include <cdcr/model/se3.hpp>
#include <cdcr/model/types.hpp>

#include "sim/simulated_robot.hpp"
#include "sim/workspace_sampler.hpp"

namespace cdcr::sim {

struct CollectedSample {
  model::JointVector<double> joints;     // as sampled
  model::CableVector<double> cables_mm;  // as commanded
  model::Pose<double> nominal_pose;      // nominal FK of the commanded cables
  double payload_kg = 0.0;               // carried while measured, known (not noise)
  Measurement measurement;
};

struct MeanPoseError {
  double position_mm = 0.0;
  double orientation_deg = 0.0;
};

struct CollectionSummary {
  int samples = 0;
  MeanPoseError initial;      // nominal pose vs. measured pose (Table 2)
  MeanPoseError noise_floor;  // true pose vs. measured pose: what no model can remove
};

// `samples` configurations from the sampler, measured on the robot; the
// payloads come from the robot's session seed and payload range.
std::vector<CollectedSample> collect(SimulatedRobot& robot, WorkspaceSampler& sampler, int samples);

// The default protocol: a sampler with the robot's seed and workspace limit.
std::vector<CollectedSample> collect(SimulatedRobot& robot, int samples);

CollectionSummary summarize(const std::vector<CollectedSample>& samples);

MeanPoseError mean_pose_error(const std::vector<model::Pose<double>>& reference,
                              const std::vector<model::Pose<double>>& poses);

}  // namespace cdcr::sim
