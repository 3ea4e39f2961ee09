#include "power_up_estimates.hpp"

#include <memory>
#include <stdexcept>
#include <string>

#include "cdcr/firmware/hysteresis_tracker.hpp"
#include "cdcr/firmware/kinematics.hpp"

namespace cdcr::cli {

PowerUpEstimates estimates_from_power_up(const model::ImageView& image, const Eigen::MatrixXd& cables_mm) {
  if (image.extra_inputs > 0) throw std::invalid_argument("a payload model has no hysteresis block");
  // The model as the runtime binds it (firmware::load_model); large, so not
  // on the stack.
  const auto robot = std::make_unique<firmware::RobotModel>();
  robot->image = image;
  model::Status status = model::geometry_from_image(image, robot->geometry);
  if (status == model::Status::ok) status = robot->correction.bind(image);
  if (status == model::Status::ok) status = robot->uncertainty.bind(image);
  if (status != model::Status::ok) throw std::invalid_argument(std::string("image: ") + model::to_string(status));
  robot->compensated = true;
  const auto tracker = std::make_unique<firmware::HysteresisTracker>();
  tracker->bind(*robot);  // the state unknown, as at power-up
  if (!tracker->active()) throw std::invalid_argument("the image has no hysteresis block");

  PowerUpEstimates result;
  result.estimates.reserve(static_cast<std::size_t>(cables_mm.rows()));
  for (Eigen::Index i = 0; i < cables_mm.rows(); ++i) {
    const firmware::Cables commanded = cables_mm.row(i).transpose().cast<firmware::Scalar>();
    firmware::PoseEstimate estimate;
    const firmware::Cables& effective = tracker->track(commanded);
    tracker->hold_history(robot->correction);
    if (const model::Status s = firmware::estimate_pose(*robot, effective, estimate); s != model::Status::ok) {
      throw std::invalid_argument("sample " + std::to_string(i + 1) + ": " + model::to_string(s));
    }
    tracker->begin_variance(*robot, estimate);
    model::PoseUncertainty<firmware::Scalar> radii = firmware::estimate_uncertainty(*robot, estimate);
    tracker->widen(*robot, radii);
    if (!tracker->known()) result.unknown_rows = static_cast<int>(i) + 1;
    result.estimates.push_back(training::firmware_estimate(estimate.pose, radii));
  }
  return result;
}

}  // namespace cdcr::cli
