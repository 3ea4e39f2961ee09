#include "sim/data_collection.hpp"

#include <stdexcept>
#include <string>

#include <cdcr/model/chain.hpp>
#include <cdcr/model/pose_error_summary.hpp>

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

}  // namespace

std::vector<CollectedSample> collect(SimulatedRobot& robot, WorkspaceSampler& sampler, int samples) {
  if (samples < 0) throw std::invalid_argument("the sample count must not be negative");
  const PayloadConfig& payload = robot.config().payload;
  RandomStream payloads(robot.config().session_seed(), StreamId::payload);
  std::vector<CollectedSample> result;
  result.reserve(static_cast<std::size_t>(samples));
  for (int i = 0; i < samples; ++i) {
    const WorkspaceSample command = sampler.next();
    CollectedSample sample;
    sample.joints = command.joints;
    sample.cables_mm = command.cables_mm;
    sample.nominal_pose = nominal_pose(command.cables_mm, robot.nominal_geometry());
    if (payload.enabled) sample.payload_kg = payloads.uniform(payload.min_kg, payload.max_kg);
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
  return summary;
}

}  // namespace cdcr::sim
