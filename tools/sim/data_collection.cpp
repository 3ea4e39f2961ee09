#include "sim/data_collection.hpp"

#include <stdexcept>
#include <string>

#include <cdcr/model/chain.hpp>
#include <cdcr/model/hysteresis.hpp>

#include "sim/random_stream.hpp"

namespace cdcr::sim {
namespace {

model::Pose<double> nominal_pose(const model::CableVector<double>& cables_mm,
                                 const model::RobotGeometry<double>& geometry) {
  model::JointVector<double> joints;
  model::Pose<double> pose;
  model::Status status = model::joints_from_cables(cables_mm, geometry, joints);
  if (status == model::Status::ok) status = model::forward_kinematics(joints, geometry, pose);
  if (status != model::Status::ok) {
    throw std::invalid_argument(std::string("nominal forward kinematics failed: ") + model::to_string(status));
  }
  return pose;
}

model::CableVector<double> current_cables(const CableFriction& friction) {
  model::CableVector<double> cables(friction.cables());
  for (int c = 0; c < friction.cables(); ++c) cables[c] = friction.commanded_mm()[static_cast<std::size_t>(c)];
  return cables;
}

}  // namespace

double move_and_settle_s(const model::CableVector<double>& from_mm, const model::CableVector<double>& to_mm,
                         const MotionSequenceConfig& motion) {
  return (to_mm - from_mm).cwiseAbs().maxCoeff() / motion.cable_speed_mm_per_s + motion.settle_s;
}

double home(SimulatedRobot& robot) {
  model::CableVector<double> approach_mm, home_mm;
  const model::Status status = model::homing_waypoints(robot.nominal_geometry(), approach_mm, home_mm);
  if (status != model::Status::ok) {
    throw std::invalid_argument(std::string("homing move: ") + model::to_string(status));
  }
  const CableFriction* friction = robot.friction();
  if (friction != nullptr) {
    const double travel_mm = model::homing_travel_mm(approach_mm, home_mm);
    const double widest_mm = friction->largest_width_mm();
    if (!(travel_mm >= 2.0 * widest_mm)) {
      throw std::invalid_argument("the homing move takes every cable " + std::to_string(travel_mm) +
                                  " mm, less than twice the widest friction play (" + std::to_string(widest_mm) +
                                  " mm): the state at home would depend on the state before");
    }
  }
  // Just powered up, the robot stands straight: at home, with an unknown state.
  const model::CableVector<double> start_mm =
      friction != nullptr && friction->has_position() ? current_cables(*friction) : home_mm;
  robot.move_cables(start_mm);
  const MotionSequenceConfig& motion = robot.config().motion;
  double duration_s = move_and_settle_s(start_mm, approach_mm, motion);
  robot.move_cables(approach_mm);
  duration_s += move_and_settle_s(approach_mm, home_mm, motion);
  robot.move_cables(home_mm);
  return duration_s;
}

std::vector<CollectedSample> collect(SimulatedRobot& robot, WorkspaceSampler& sampler, int samples) {
  if (samples < 0) throw std::invalid_argument("the sample count must not be negative");
  const PayloadConfig& payload = robot.config().payload;
  RandomStream payloads(robot.config().session_seed(), StreamId::payload);
  std::vector<CollectedSample> result;
  result.reserve(static_cast<std::size_t>(samples));
  // With the hysteresis the session is a motion sequence that starts with the homing move.
  const bool sequence = robot.friction() != nullptr;
  double time_s = 0.0;
  model::CableVector<double> position_mm;
  if (sequence) {
    home(robot);  // t = 0: at home, settled
    position_mm = current_cables(*robot.friction());
  }
  for (int i = 0; i < samples; ++i) {
    const WorkspaceSample command = sampler.next();
    CollectedSample sample;
    sample.joints = command.joints;
    sample.cables_mm = command.cables_mm;
    sample.nominal_pose = nominal_pose(command.cables_mm, robot.nominal_geometry());
    if (payload.enabled) sample.payload_kg = payloads.uniform(payload.min_kg, payload.max_kg);
    if (sequence) {
      time_s += move_and_settle_s(position_mm, command.cables_mm, robot.config().motion);
      position_mm = command.cables_mm;
      sample.in_sequence = true;
      sample.time_s = time_s;
      sample.frictionless_pose = robot.true_pose(command.cables_mm, sample.payload_kg);
    }
    sample.measurement = robot.measure(command.cables_mm, sample.payload_kg);
    result.push_back(sample);
  }
  return result;
}

std::vector<CollectedSample> collect(SimulatedRobot& robot, int samples) {
  WorkspaceSampler sampler(robot.nominal_geometry(), robot.config().workspace_theta_max_rad,
                           robot.config().session_seed());
  return collect(robot, sampler, samples);
}

MeanPoseError mean_pose_error(const std::vector<model::Pose<double>>& reference,
                              const std::vector<model::Pose<double>>& poses) {
  if (reference.size() != poses.size()) throw std::invalid_argument("pose lists differ in length");
  const model::PoseErrorSummary s = model::summarize_pose_errors(reference.data(), poses.data(), poses.size());
  return MeanPoseError{s.mean_position_mm, s.mean_orientation_deg};
}

CollectionSummary summarize(const std::vector<CollectedSample>& samples) {
  std::vector<model::Pose<double>> nominal, truth, measured;
  for (const CollectedSample& s : samples) {
    nominal.push_back(s.nominal_pose);
    truth.push_back(s.measurement.true_pose);
    measured.push_back(s.measurement.measured_pose);
  }
  CollectionSummary summary;
  summary.samples = static_cast<int>(samples.size());
  summary.initial = mean_pose_error(measured, nominal);
  summary.noise_floor = mean_pose_error(measured, truth);
  summary.sequence = !samples.empty() && samples.front().in_sequence;
  if (summary.sequence) {
    std::vector<model::Pose<double>> frictionless;
    for (const CollectedSample& s : samples) frictionless.push_back(s.frictionless_pose);
    summary.hysteresis = model::summarize_pose_errors(frictionless.data(), truth.data(), truth.size());
  }
  return summary;
}

}  // namespace cdcr::sim
