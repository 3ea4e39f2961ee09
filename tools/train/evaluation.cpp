#include "evaluation.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "cdcr/firmware/compensated_pose.hpp"
#include "cdcr/model/compensated_kinematics.hpp"
#include "cdcr/model/image_compliance.hpp"
#include "cdcr/model/pose_error_summary.hpp"

namespace cdcr::training {

using model::kDegreesPerRadian;

MeanErrors mean_errors(const std::vector<model::Pose<double>>& reference, const std::vector<model::Pose<double>>& poses) {
  const Fidelity f = compare_poses(reference, poses);
  return MeanErrors{f.mean_position_mm, f.mean_orientation_deg};
}

Fidelity compare_poses(const std::vector<model::Pose<double>>& reference, const std::vector<model::Pose<double>>& poses) {
  if (reference.size() != poses.size() || reference.empty()) throw std::invalid_argument("pose lists differ in size");
  return model::summarize_pose_errors(reference.data(), poses.data(), poses.size());
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

// The board's path (firmware::estimate_compensated_pose) with the given
// accumulator: pose, radii and flags.
template <typename Accumulator>
std::vector<FirmwareEstimate> estimates_with(const model::ImageView& image, const Eigen::MatrixXd& cables_mm,
                                             const Eigen::VectorXd& payload_kg,
                                             const Eigen::MatrixXd& history_inputs) {
  if (image.extra_inputs > 0 && payload_kg.size() == 0) {
    throw std::invalid_argument("the model takes a payload input and the data have no payload_kg column");
  }
  if (image.extra_inputs > 0 && payload_kg.size() != cables_mm.rows()) {
    throw std::invalid_argument("one payload per sample is needed");
  }
  if (model::takes_history(image.encoding) &&
      (history_inputs.rows() != cables_mm.rows() || history_inputs.cols() != cables_mm.cols())) {
    throw std::invalid_argument("the model takes the cables' history and the rows have none");
  }
  firmware::Geometry geometry;
  if (const model::Status s = model::geometry_from_image(image, geometry); s != model::Status::ok) {
    throw std::invalid_argument(std::string("image geometry: ") + model::to_string(s));
  }
  model::GpCorrection<float, Accumulator, firmware::kMaxSegments> correction;
  firmware::Uncertainty uncertainty;
  if (const model::Status s = correction.bind(image); s != model::Status::ok) {
    throw std::invalid_argument(std::string("image: ") + model::to_string(s));
  }
  if (const model::Status s = uncertainty.bind(image); s != model::Status::ok) {
    throw std::invalid_argument(std::string("image: ") + model::to_string(s));
  }
  firmware::Compliance compliance;
  model::compliance_from_image(image, compliance);
  std::vector<FirmwareEstimate> estimates;
  estimates.reserve(static_cast<std::size_t>(cables_mm.rows()));
  for (Eigen::Index i = 0; i < cables_mm.rows(); ++i) {
    const firmware::Cables cables = cables_mm.row(i).transpose().cast<float>();
    if (image.extra_inputs > 0) correction.set_payload_kg(static_cast<float>(payload_kg[i]));
    if (correction.takes_history()) {
      const firmware::Cables history = history_inputs.row(i).transpose().cast<float>();
      correction.set_history_inputs(history.data());
    }
    firmware::PoseEstimate estimate;
    if (const model::Status s =
            firmware::estimate_compensated_pose(geometry, correction, uncertainty, compliance, cables, estimate);
        s != model::Status::ok) {
      throw std::invalid_argument("sample " + std::to_string(i + 1) + ": " + model::to_string(s));
    }
    const model::PoseUncertainty<float> u = uncertainty.evaluate(estimate.kernel_coordinates, estimate.pose.position_mm);
    estimates.push_back(firmware_estimate(estimate.pose, u));
  }
  return estimates;
}

template <typename Accumulator>
std::vector<model::Pose<double>> firmware_poses_with(const model::ImageView& image, const Eigen::MatrixXd& cables_mm,
                                                     const Eigen::VectorXd& payload_kg,
                                             const Eigen::MatrixXd& history_inputs) {
  std::vector<model::Pose<double>> poses;
  for (const FirmwareEstimate& e : estimates_with<Accumulator>(image, cables_mm, payload_kg, history_inputs)) poses.push_back(e.pose);
  return poses;
}

}  // namespace

std::vector<model::Pose<double>> firmware_poses(const model::ImageView& image, const Eigen::MatrixXd& cables_mm,
                                                FirmwareAccumulator accumulator, const Eigen::VectorXd& payload_kg,
                                                const Eigen::MatrixXd& history_inputs) {
  switch (accumulator) {
    case FirmwareAccumulator::compensated_float32:
      return firmware_poses_with<model::CompensatedFloat>(image, cables_mm, payload_kg, history_inputs);
    case FirmwareAccumulator::float32:
      return firmware_poses_with<float>(image, cables_mm, payload_kg, history_inputs);
    case FirmwareAccumulator::float64:
      break;
  }
  return firmware_poses_with<double>(image, cables_mm, payload_kg, history_inputs);
}

FirmwareEstimate firmware_estimate(const model::Pose<float>& pose, const model::PoseUncertainty<float>& radii) {
  FirmwareEstimate e;
  e.pose = pose.cast<double>();
  e.uncertainty.r95_mm = radii.r95_mm;
  e.uncertainty.r95_deg = radii.r95_deg;
  e.uncertainty.latent_share = radii.latent_share;
  e.uncertainty.outside_range = radii.outside_range;
  e.uncertainty.extrapolating = radii.extrapolating;
  return e;
}

std::vector<FirmwareEstimate> firmware_estimates(const model::ImageView& image, const Eigen::MatrixXd& cables_mm,
                                                const Eigen::VectorXd& payload_kg,
                                             const Eigen::MatrixXd& history_inputs) {
  return estimates_with<double>(image, cables_mm, payload_kg, history_inputs);
}

CoverageCheck check_coverage(const std::vector<model::Pose<double>>& measured,
                             const std::vector<FirmwareEstimate>& estimates) {
  if (measured.size() != estimates.size() || measured.empty()) throw std::invalid_argument("pose lists differ in size");
  CoverageCheck c;
  c.samples = static_cast<int>(measured.size());
  std::vector<double> radii_mm, radii_deg, shares;
  for (std::size_t i = 0; i < measured.size(); ++i) {
    const model::PoseError<double> e = model::pose_error(measured[i], estimates[i].pose);
    const model::PoseUncertainty<double>& u = estimates[i].uncertainty;
    if (e.position_mm <= u.r95_mm) c.position_coverage += 1.0;
    if (e.orientation_rad * kDegreesPerRadian <= u.r95_deg) c.orientation_coverage += 1.0;
    if (u.extrapolating) ++c.extrapolating;
    if (u.outside_range) ++c.outside_range;
    radii_mm.push_back(u.r95_mm);
    radii_deg.push_back(u.r95_deg);
    shares.push_back(u.latent_share);
  }
  c.position_coverage /= c.samples;
  c.orientation_coverage /= c.samples;
  const auto median = [](std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  c.median_r95_mm = median(radii_mm);
  c.median_r95_deg = median(radii_deg);
  c.median_latent_share = median(shares);
  return c;
}

}  // namespace cdcr::training
