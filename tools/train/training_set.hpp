#pragma once
// Turns a measured dataset into GP training pairs: inputs are the encoded
// joint variables of each sample (nominal inverse of the commanded cables),
// outputs the tip error twists of eq. (18), ordered (v, omega).

#include <vector>

#include <Eigen/Core>

#include "cdcr/model/geometry.hpp"
#include "cdcr/model/input_encoding.hpp"
#include "cdcr/model/se3.hpp"
#include "dataset/dataset.hpp"

namespace cdcr::training {

struct TrainingSet {
  Eigen::MatrixXd cables_mm;     // samples x 4n, as commanded
  Eigen::MatrixXd bends;         // samples x 2n, stacked bend vectors
  Eigen::MatrixXd inputs;        // samples x D, encoded
  Eigen::MatrixXd error_twists;  // samples x 6
  std::vector<model::Pose<double>> nominal;
  std::vector<model::Pose<double>> measured;

  int size() const { return static_cast<int>(inputs.rows()); }
  TrainingSet subset(const std::vector<int>& rows) const;
};

// Throws std::invalid_argument naming the sample (1-based data row) whose
// cables the nominal model rejects, or if the dataset has no poses or a
// segment count other than the geometry's.
TrainingSet make_training_set(const dataset::Dataset& data, const model::RobotGeometry<double>& geometry,
                              model::InputEncoding encoding);

// Encoded GP inputs for stacked bend vectors (rows).
Eigen::MatrixXd encode_rows(const Eigen::MatrixXd& bends, model::InputEncoding encoding);

}  // namespace cdcr::training
