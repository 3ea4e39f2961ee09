#pragma once
// A small TrainedModel with random but valid values, for the flash image,
// exporter and CLI tests. The numbers mean nothing physically; every field
// is distinct so a value landing in the wrong slot shows up.

#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include <Eigen/Core>

#include "trained_model/trained_model.hpp"

namespace cdcr::test_support {

struct SyntheticModelOptions {
  int training_points = 5;
  int segments = 2;
  model::InputEncoding encoding = model::InputEncoding::bend_vector;
  std::uint32_t seed = 20200921;
  // One more input after the bend pairs: the payload, 0 to 1 kg.
  bool payload_input = false;
  // The cable-fit encoding: after the bend pairs, each segment's common
  // mode (-1.5 to 0 mm) and pair imbalance (-1 to 1 mm).
  bool cable_residuals = false;
  // A history encoding: after the residuals, where each cable last moved
  // (-1 to 1, 4 per segment); needs hysteresis_operators, whose last
  // operator keeps it.
  bool history = false;
  // The correction's size: the output means and scales of the position
  // outputs times the first, of the rotation outputs times the second (a
  // trained model's correction is millimetres and milliradians).
  double position_output_factor = 1.0;
  double rotation_output_factor = 1.0;
  // Play operators per cable of a hysteresis model (0: none, a joints-only
  // model): widths 0.2 to 0.7 mm, weights summing to 0.6 to 1 per cable,
  // the homing lags the homing move leaves on this geometry.
  int hysteresis_operators = 0;
  // Cables per segment: the paper's four at 90 degrees, or three at 120
  // (an image with the cables block).
  int cables_per_segment = 4;
};

// A hysteresis model for `geometry` with random but valid values (widths
// 0.2 to 0.7 mm, the weights of each cable summing to 0.6 to 1), its homing
// lags computed from the homing move.
template <typename Rng>
model::HysteresisModel<double> synthetic_hysteresis(const model::RobotGeometry<double>& geometry, int operators,
                                                    Rng& rng) {
  const auto uniform = [&rng](double low, double high) { return std::uniform_real_distribution<double>(low, high)(rng); };
  model::HysteresisModel<double> h;
  h.cables = geometry.cable_count();
  h.operators = operators;
  for (int c = 0; c < h.cables; ++c) {
    const double total = uniform(0.6, 1.0);
    for (int k = 0; k < operators; ++k) {
      h.widths_mm[c][k] = uniform(0.2, 0.7);
      h.weights[c][k] = total / operators;
    }
  }
  model::CableVector<double> approach_mm, home_mm;
  model::homing_waypoints(geometry, approach_mm, home_mm);
  model::compute_homing_lags(h, approach_mm, home_mm);
  return h;
}

inline training::TrainedModel synthetic_trained_model(const SyntheticModelOptions& options = {}) {
  std::mt19937 rng(options.seed);
  const auto uniform = [&rng](double low, double high) { return std::uniform_real_distribution<double>(low, high)(rng); };

  training::TrainedModel m;
  m.encoding = options.cable_residuals ? model::InputEncoding::bend_vector_cable_fit : options.encoding;
  m.encoding = model::with_history(m.encoding, options.history);
  m.geometry = model::RobotGeometry<double>::uniform(options.segments, 120.0, 67.0);
  m.geometry.segments[options.segments - 1].backbone_length_mm = 95.5;  // not all segments alike
  if (options.cables_per_segment != 4) {
    for (int s = 0; s < options.segments; ++s) {
      m.geometry.segments[s].cables = model::CableLayout<double>::evenly_spaced(options.cables_per_segment);
    }
  }

  const int n = options.training_points;
  const int residuals_per_segment = options.cables_per_segment - 2;
  const int residuals = options.cable_residuals ? residuals_per_segment * options.segments : 0;
  const int history = options.history ? options.cables_per_segment * options.segments : 0;
  const int d = 2 * options.segments + residuals + history + (options.payload_input ? 1 : 0);
  m.inputs.resize(n, d);
  for (int i = 0; i < n; ++i) {
    for (int s = 0; s < options.segments; ++s) {
      const double alpha_rad = uniform(-3.0, 3.0);
      const double theta_rad = uniform(0.05, 1.2);
      if (m.encoding != model::InputEncoding::joint_angles) {
        m.inputs(i, 2 * s) = theta_rad * std::cos(alpha_rad);
        m.inputs(i, 2 * s + 1) = theta_rad * std::sin(alpha_rad);
      } else {
        m.inputs(i, 2 * s) = alpha_rad;
        m.inputs(i, 2 * s + 1) = theta_rad;
      }
    }
    for (int s = 0; s < options.segments && residuals > 0; ++s) {
      m.inputs(i, 2 * options.segments + residuals_per_segment * s) = uniform(-1.5, 0.0);
      if (residuals_per_segment == 2) m.inputs(i, 2 * options.segments + 2 * s + 1) = uniform(-1.0, 1.0);
    }
    for (int c = 0; c < history; ++c) m.inputs(i, 2 * options.segments + residuals + c) = uniform(-1.0, 1.0);
    if (options.payload_input) m.inputs(i, d - 1) = uniform(0.0, 1.0);
  }
  if (options.payload_input) m.default_payload_kg = 0.375;
  m.input_mean = m.inputs.colwise().mean().transpose();
  m.input_scale.resize(d);
  m.length_scales.resize(d);
  for (int k = 0; k < d; ++k) {
    m.input_scale[k] = uniform(0.3, 1.5);
    m.length_scales[k] = uniform(0.5, 2.5);
  }
  for (int k = 0; k < 6; ++k) {
    m.output_mean[k] = uniform(-2.0, 2.0);
    m.output_scale[k] = uniform(0.1, 3.0);
    m.signal_variance[k] = uniform(0.5, 2.0);
    m.noise_variance[k] = uniform(1e-4, 1e-2);
  }
  for (int k = 0; k < 6; ++k) {
    const double factor = k < 3 ? options.position_output_factor : options.rotation_output_factor;
    m.output_mean[k] *= factor;
    m.output_scale[k] *= factor;
  }
  m.alpha.resize(n, 6);
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < 6; ++k) m.alpha(i, k) = uniform(-1.0, 1.0);
  }

  if (options.hysteresis_operators > 0) m.hysteresis = synthetic_hysteresis(m.geometry, options.hysteresis_operators, rng);

  m.dataset_hash = 0xcbf29ce484222325ull ^ options.seed;
  m.created_unix_s = 1700000000;  // 2023-11-14T22:13:20Z
  m.validation_samples = 70;
  m.metrics = model::ImageMetrics{3.25f, 1.5f, 0.75f, 0.25f, 0.004f, 0.001f, 0.0005f, 0.0001f};
  m.trainer = "cdcr-test 0.1.0";
  return m;
}

}  // namespace cdcr::test_support
