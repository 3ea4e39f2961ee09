#pragma once
// Turns a measured dataset into GP training pairs: inputs are the encoded
// joint variables of each sample (the least-squares fit of all its cables,
// model/cable_fit.hpp), with the fit's residuals for the cable-fit encoding,
// outputs the tip error twists of eq. (18), ordered (v, omega). A dataset
// with a payload column gives one more input, the payload (kg), last.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "cdcr/model/geometry.hpp"
#include "cdcr/model/input_encoding.hpp"
#include "cdcr/model/se3.hpp"
#include "dataset/dataset.hpp"

namespace cdcr::training {

struct TrainingSet {
  Eigen::MatrixXd cables_mm;     // samples x cables, as commanded (a sequence with a hysteresis model: effective)
  // A sequence with a hysteresis model: the commanded lengths (cables_mm
  // then holds the effective ones); empty otherwise.
  Eigen::MatrixXd commanded_mm;
  Eigen::MatrixXd bends;         // samples x 2n, stacked bend vectors
  // The cable fit's residuals as inputs (model::residual_inputs): per
  // segment the common mode, and with four cables the pairs' imbalance.
  Eigen::MatrixXd cable_residuals;
  // A sequence whose model keeps the cables' history: samples x cables,
  // where each cable last moved (model::history_inputs); empty otherwise.
  Eigen::MatrixXd history_inputs;
  Eigen::VectorXd payload_kg;    // samples, or empty: the data carried no payload column
  Eigen::MatrixXd inputs;        // samples x D, encoded (and the payload last, when there is one)
  model::InputEncoding encoding = model::InputEncoding::bend_vector;  // of `inputs`
  Eigen::MatrixXd error_twists;  // samples x 6
  std::vector<model::Pose<double>> nominal;
  std::vector<model::Pose<double>> measured;

  // Rows with a segment far from consistent with constant curvature
  // (model::far_from_consistent), and rows that bend a segment beyond its
  // theta_max (trained on; the runtime refuses such cables).
  int far_from_consistent_rows = 0;
  int beyond_limit_rows = 0;

  int size() const { return static_cast<int>(inputs.rows()); }
  bool has_payload() const { return payload_kg.size() > 0; }
  TrainingSet subset(const std::vector<int>& rows) const;
};

// Rows held out for validation and the rest for training, both sorted.
struct Split {
  std::vector<int> train;
  std::vector<int> test;
};

// test_count samples drawn at random (seeded), the rest in order for training.
Split random_split(int samples, int test_count, std::uint64_t seed);

// Throws std::invalid_argument naming the sample (1-based data row) whose
// cables are impossible (not finite, not positive), or if the dataset has no
// poses or a segment count other than the geometry's; cables inconsistent
// with constant curvature, or beyond the bend limit, are rows like any
// other (and counted). The payload column, when the dataset has one,
// becomes an input unless with_payload is false.
TrainingSet make_training_set(const dataset::Dataset& data, const model::RobotGeometry<double>& geometry,
                              model::InputEncoding encoding, bool with_payload = true);

// Encoded GP inputs for stacked bend vectors (rows).
Eigen::MatrixXd encode_rows(const Eigen::MatrixXd& bends, model::InputEncoding encoding);

// The GP inputs: the encoded bends, the cable residuals and the history
// when the encoding takes them, then the payload column when payload_kg is
// not empty (one value per row).
Eigen::MatrixXd model_inputs(const Eigen::MatrixXd& bends, const Eigen::MatrixXd& cable_residuals,
                             const Eigen::MatrixXd& history_inputs, const Eigen::VectorXd& payload_kg,
                             model::InputEncoding encoding);

// The same rows with their cable lengths rounded to float32, as the board
// reads them: the bends, residuals, nominal poses and error twists of those
// lengths (not for sets whose nominal poses are sagged).
TrainingSet with_float_cables(const TrainingSet& set, const model::RobotGeometry<double>& geometry,
                              model::InputEncoding encoding);

// The same rows with their inputs in another encoding (a history encoding
// needs the rows' history_inputs).
TrainingSet with_encoding(const TrainingSet& set, model::InputEncoding encoding);

}  // namespace cdcr::training
