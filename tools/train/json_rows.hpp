#pragma once
// A matrix as the comparisons with scikit-learn exchange it: a JSON array of
// its rows. Header-only, so that the training library itself does not need
// nlohmann_json; whoever includes it links it.

#include <cstddef>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace cdcr::training {

inline nlohmann::json json_rows(const Eigen::MatrixXd& m) {
  nlohmann::json j = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    std::vector<double> row(static_cast<std::size_t>(m.cols()));
    for (Eigen::Index k = 0; k < m.cols(); ++k) row[static_cast<std::size_t>(k)] = m(i, k);
    j.push_back(row);
  }
  return j;
}

}  // namespace cdcr::training
