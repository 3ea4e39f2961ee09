#pragma once
// The trainer's result in double precision: everything the flash image holds,
// before conversion to float32 kernel coordinates (see model/flash-image-v1.md).

#include <cstdint>
#include <string>

#include <Eigen/Core>

#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/geometry.hpp"
#include "cdcr/model/input_encoding.hpp"

namespace cdcr::training {

using Vector6d = Eigen::Matrix<double, 6, 1>;

struct TrainedModel {
  model::InputEncoding encoding = model::InputEncoding::bend_vector;
  model::RobotGeometry<double> geometry;

  Eigen::VectorXd input_mean;     // D
  Eigen::VectorXd input_scale;    // D
  Eigen::VectorXd length_scales;  // D, normalised input units, shared by all outputs
  Vector6d output_mean = Vector6d::Zero();
  Vector6d output_scale = Vector6d::Ones();
  Vector6d signal_variance = Vector6d::Ones();
  Vector6d noise_variance = Vector6d::Constant(1e-2);

  Eigen::MatrixXd inputs;  // N x D encoded training inputs, not normalised
  Eigen::MatrixXd alpha;   // N x 6, (K + noise I)^-1 y_n per normalised output

  // Metadata carried into the image.
  std::uint64_t dataset_hash = 0;
  std::int64_t created_unix_s = 0;
  std::uint32_t validation_samples = 0;
  model::ImageMetrics metrics{};
  std::string trainer = "cdcr";

  int training_points() const { return static_cast<int>(inputs.rows()); }
  int input_dims() const { return static_cast<int>(inputs.cols()); }
};

}  // namespace cdcr::training
