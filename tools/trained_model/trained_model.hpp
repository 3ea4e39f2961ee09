#pragma once
// The trainer's result in double precision: everything the flash image holds,
// before conversion to float32 kernel coordinates (see model/flash-image-v2.md).

#include <cstdint>
#include <string>

#include <Eigen/Core>

#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/geometry.hpp"
#include "cdcr/model/hysteresis.hpp"
#include "cdcr/model/input_encoding.hpp"
#include "cdcr/model/payload_compliance.hpp"

namespace cdcr::training {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// The predictive variance as the image's variance block holds it (rank 0:
// none); see predictive_variance.hpp for what the factors are.
struct VarianceFactor {
  Eigen::MatrixXd points;            // R x D kernel coordinates
  Eigen::MatrixXd inducing_factor;   // R x R lower triangle L_u
  Eigen::MatrixXd posterior_factor;  // R x R lower triangle L_c
  double position_scale = 1.0;
  double orientation_scale = 1.0;
  double extrapolation_variance = 1.0;
  double jitter = 0.0;  // added to R_uu's diagonal before L_u

  int rank() const { return static_cast<int>(points.rows()); }
};

struct TrainedModel {
  model::ImageModelKind kind = model::ImageModelKind::exact_gp;
  model::InputEncoding encoding = model::InputEncoding::bend_vector;
  model::RobotGeometry<double> geometry;

  Eigen::VectorXd input_mean;     // D
  Eigen::VectorXd input_scale;    // D
  Eigen::VectorXd length_scales;  // D, normalised input units, shared by all outputs
  Vector6d output_mean = Vector6d::Zero();
  Vector6d output_scale = Vector6d::Ones();
  Vector6d signal_variance = Vector6d::Ones();
  Vector6d noise_variance = Vector6d::Constant(1e-2);

  // The points: an exact model's N training inputs, a sparse model's M
  // inducing inputs; and their weights, alpha or the sparse beta.
  Eigen::MatrixXd inputs;  // points x D encoded inputs, not normalised
  Eigen::MatrixXd alpha;   // points x 6; exact: (K + noise I)^-1 y_n per normalised output

  // Data rows the model was fitted on; 0 means the points (an exact model's
  // rows are its points). A sparse model must say.
  std::uint32_t fitted_rows = 0;
  // Per-input range of the fitted rows, raw encoded units (D each), so the
  // board can tell when it extrapolates; empty: the writer takes the range of
  // `inputs`, which is the fitted rows' for an exact model.
  Eigen::VectorXd input_min, input_max;
  VarianceFactor variance;
  // The payload the board uses until one arrives (a payload model only):
  // the mean over the fitted rows.
  double default_payload_kg = 0.0;
  // The cables' identified hysteresis (empty: a joints-only model). The GP's
  // inputs are then the joints of the effective cable lengths.
  model::HysteresisModel<double> hysteresis;
  // The segments' compliance under the tip load (empty: none; a payload
  // model only). The nominal poses the GP was fitted against are then the
  // sagged ones, and the GP's inputs stay the commanded bends.
  model::PayloadCompliance<double> compliance;

  // Metadata carried into the image.
  std::uint64_t dataset_hash = 0;
  std::int64_t created_unix_s = 0;
  std::uint32_t validation_samples = 0;
  model::ImageMetrics metrics{};
  std::string trainer = "cdcr";

  int training_points() const { return static_cast<int>(inputs.rows()); }  // the points, N or M
  int input_dims() const { return static_cast<int>(inputs.cols()); }
  // Inputs after the encoding's (the bend pairs, and the cable residuals for
  // the cable-fit encoding): 1 when the model takes the payload.
  int extra_inputs() const {
    return input_dims() - model::encoded_input_count(encoding, geometry);
  }
  bool has_payload_input() const { return extra_inputs() > 0; }

  // Records the range of the rows the model is fitted on (rows x D, raw).
  void set_input_range(const Eigen::MatrixXd& fitted_inputs) {
    input_min = fitted_inputs.colwise().minCoeff().transpose();
    input_max = fitted_inputs.colwise().maxCoeff().transpose();
  }
};

}  // namespace cdcr::training
