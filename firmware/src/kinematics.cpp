#include "cdcr/firmware/kinematics.hpp"

#include "cdcr/firmware/compensated_pose.hpp"

namespace cdcr::firmware {

model::Status estimate_pose(const RobotModel& model, const Cables& cables_mm, PoseEstimate& estimate) {
  if (model.compensated) {
    return estimate_compensated_pose(model.geometry, model.correction, model.uncertainty, model.compliance, cables_mm,
                                     estimate);
  }
  Joints joints;
  if (const model::Status s = model::joints_from_cables(cables_mm, model.geometry, joints, kCableResolutionMm);
      s != model::Status::ok) {
    return s;
  }
  estimate.pose = model::forward_kinematics_bend(model::bend_from_joints(joints), model.geometry);
  estimate.joints = joints;
  estimate.compensated = false;
  estimate.outside_range = false;
  return model::Status::ok;
}

model::PoseUncertainty<Scalar> estimate_uncertainty(const RobotModel& model, const PoseEstimate& estimate) {
  if (!estimate.compensated || !model.uncertainty.bound()) return model::PoseUncertainty<Scalar>{};
  return model.uncertainty.evaluate(estimate.kernel_coordinates, estimate.pose.position_mm);
}

void PoseVariance::begin(const Uncertainty& uncertainty, const PoseEstimate& estimate, std::uint8_t sequence) {
  uncertainty.begin_evaluation(estimate.kernel_coordinates, estimate.pose.position_mm, evaluation_);
  running_ = true;
  running_sequence_ = sequence;
}

bool PoseVariance::continue_slice(const Uncertainty& uncertainty) {
  uncertainty.continue_evaluation(evaluation_, kUncertaintyUnitsPerCycle);
  if (!uncertainty.evaluation_finished(evaluation_)) return false;
  running_ = false;
  result_ = uncertainty.evaluation_result(evaluation_);
  has_result_ = true;
  result_sequence_ = running_sequence_;
  return true;
}

model::Status SolverCorrection::begin_evaluation(const Joints& bend, Evaluation& evaluation,
                                                 bool with_gradient) const {
  if (compliance_ == nullptr || compliance_->empty()) return correction_->begin_evaluation(bend, evaluation, with_gradient);
  return correction_->begin_evaluation(commanded_bends_of(*compliance_, *geometry_, correction_->payload_kg(), bend),
                                       evaluation, with_gradient);
}

std::uint32_t SolverCorrection::continue_evaluation(Evaluation& evaluation, std::uint32_t max_units) const {
  return correction_->continue_evaluation(evaluation, max_units);
}

bool SolverCorrection::evaluation_finished(const Evaluation& evaluation) const {
  return correction_->evaluation_finished(evaluation);
}

bool SolverCorrection::evaluation_has_gradient(const Evaluation& evaluation) const {
  return correction_->evaluation_has_gradient(evaluation);
}

void SolverCorrection::evaluation_result(const Evaluation& evaluation, model::Twist<Scalar>& eps,
                                         model::Jacobian<Scalar, kMaxSegments>& d_eps_d_bend) const {
  correction_->evaluation_result(evaluation, eps, d_eps_d_bend);
}

}  // namespace cdcr::firmware
