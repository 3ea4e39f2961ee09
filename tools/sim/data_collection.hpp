#pragma once
// The paper's data collection (Section V-B) on the simulated robot: random
// workspace configurations, each commanded once and measured once, with the
// initial error of the nominal model and the simulator's noise floor. With
// the payload enabled (SimulatorConfig::payload), each sample also carries a
// payload drawn from its own stream.
//
// With the hysteresis on (source 7) the session is a motion sequence: the
// robot first performs the homing move (home()), then moves row to row along
// straight lines in cable space, and each row is measured when the robot
// has stopped there and settled; every row gets its time (MotionSequenceConfig).

#include <vector>

#include <cdcr/model/pose_error_summary.hpp>
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
  // In a motion sequence (hysteresis on): when the row was measured (s from
  // the end of the homing move), and the true pose the same commanded
  // cables give without the hysteresis.
  bool in_sequence = false;
  double time_s = 0.0;
  model::Pose<double> frictionless_pose;
};

struct MeanPoseError {
  double position_mm = 0.0;
  double orientation_deg = 0.0;
};

struct CollectionSummary {
  int samples = 0;
  MeanPoseError initial;      // nominal pose vs. measured pose (Table 2)
  MeanPoseError noise_floor;  // true pose vs. measured pose: what no model can remove
  bool sequence = false;      // a motion sequence (hysteresis on): `hysteresis` is set
  // How far the hysteresis moves the tip: the true pose against the true
  // pose of the same commanded cables without it.
  model::PoseErrorSummary hysteresis;
};

// The homing move of model::homing_waypoints for the robot's nominal
// geometry: from where the cables are (at home, the straight robot, when the
// robot has just powered up) to the approach, then home, each leg a straight
// line in cable space, with a stop and settle after each. Returns its
// duration (s) at the robot's MotionSequenceConfig. Every cable travels the
// same distance on the way home; std::invalid_argument when that is less
// than twice the widest friction play, as the state at home would then
// depend on the state before.
double home(SimulatedRobot& robot);

// The time to move from `from` to `to` along a straight line in cable space
// and settle: the largest cable change at the cable speed, plus settle_s.
double move_and_settle_s(const model::CableVector<double>& from_mm, const model::CableVector<double>& to_mm,
                         const MotionSequenceConfig& motion);


// `samples` configurations from the sampler, measured on the robot; the
// payloads come from the robot's session seed and payload range.
std::vector<CollectedSample> collect(SimulatedRobot& robot, WorkspaceSampler& sampler, int samples);

// The default protocol: a sampler with the robot's seed and workspace limit.
std::vector<CollectedSample> collect(SimulatedRobot& robot, int samples);

CollectionSummary summarize(const std::vector<CollectedSample>& samples);

MeanPoseError mean_pose_error(const std::vector<model::Pose<double>>& reference,
                              const std::vector<model::Pose<double>>& poses);

}  // namespace cdcr::sim
