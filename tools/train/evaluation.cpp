#include "evaluation.hpp"

#include <stdexcept>
#include <string>

#include "cdcr/model/compensated_kinematics.hpp"
#include "cdcr/model/pose_error_summary.hpp"

namespace cdcr::training {

MeanErrors mean_errors(const std::vector<model::Pose<double>>& reference, const std::vector<model::Pose<double>>& poses) {
  const Fidelity f = compare_poses(reference, poses);
  return MeanErrors{f.mean_position_mm, f.mean_orientation_deg};
}

Fidelity compare_poses(const std::vector<model::Pose<double>>& reference, const std::vector<model::Pose<double>>& poses) {
  if (reference.size() != poses.size() || reference.empty()) throw std::invalid_argument("pose lists differ in size");
  const model::PoseErrorSummary s = model::summarize_pose_errors(reference.data(), poses.data(), poses.size());
  return Fidelity{s.max_position_mm, s.mean_position_mm, s.max_orientation_deg, s.mean_orientation_deg};
}

std::vector<model::Pose<double>> compensated_poses(const TrainingSet& set, const Eigen::MatrixXd& error_twists) {
  std::vector<model::Pose<double>> poses;
  poses.reserve(set.nominal.size());
  for (std::size_t i = 0; i < set.nominal.size(); ++i) {
    const model::Twist<double> eps = error_twists.row(static_cast<Eigen::Index>(i)).transpose();
    poses.push_back(model::compensate(eps, set.nominal[i]));
  }
  return poses;
}

Evaluation evaluate(const TrainingSet& set, const Eigen::MatrixXd& predicted_error_twists) {
  Evaluation e;
  e.samples = set.size();
  e.initial = mean_errors(set.measured, set.nominal);
  e.compensated = mean_errors(set.measured, compensated_poses(set, predicted_error_twists));
  return e;
}

const char* to_string(FirmwareAccumulator accumulator) {
  switch (accumulator) {
    case FirmwareAccumulator::float64: return "double accumulators";
    case FirmwareAccumulator::compensated_float32: return "compensated float accumulators";
    case FirmwareAccumulator::float32: return "plain float accumulators";
  }
  return "unknown";
}

namespace {

template <typename Accumulator>
std::vector<model::Pose<double>> firmware_poses_with(const model::ImageView& image, const Eigen::MatrixXd& cables_mm) {
  model::RobotGeometry<float> geometry;
  if (const model::Status s = model::geometry_from_image(image, geometry); s != model::Status::ok) {
    throw std::invalid_argument(std::string("image geometry: ") + model::to_string(s));
  }
  model::GpCorrection<float, Accumulator> correction;
  if (const model::Status s = correction.bind(image); s != model::Status::ok) {
    throw std::invalid_argument(std::string("image: ") + model::to_string(s));
  }
  std::vector<model::Pose<double>> poses;
  poses.reserve(static_cast<std::size_t>(cables_mm.rows()));
  for (Eigen::Index i = 0; i < cables_mm.rows(); ++i) {
    const model::CableVector<float> cables = cables_mm.row(i).transpose().cast<float>();
    model::ForwardResult<float> result;
    if (const model::Status s = model::compensated_forward(cables, geometry, correction, result);
        s != model::Status::ok) {
      throw std::invalid_argument("sample " + std::to_string(i + 1) + ": " + model::to_string(s));
    }
    poses.push_back(result.compensated.cast<double>());
  }
  return poses;
}

}  // namespace

std::vector<model::Pose<double>> firmware_poses(const model::ImageView& image, const Eigen::MatrixXd& cables_mm,
                                                FirmwareAccumulator accumulator) {
  switch (accumulator) {
    case FirmwareAccumulator::compensated_float32:
      return firmware_poses_with<model::CompensatedFloat>(image, cables_mm);
    case FirmwareAccumulator::float32:
      return firmware_poses_with<float>(image, cables_mm);
    case FirmwareAccumulator::float64:
      break;
  }
  return firmware_poses_with<double>(image, cables_mm);
}

}  // namespace cdcr::training
