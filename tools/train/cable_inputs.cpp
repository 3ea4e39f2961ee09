#include "cable_inputs.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

namespace cdcr::training {

SearchResult search_on_rows(const TrainingSet& set, const TrainingOptions& options, int rows,
                            const KernelHyperparameters* initial) {
  const Normalisation n = normalisation_of(set);
  const Eigen::MatrixXd x = normalise(set.inputs, n.input_mean, n.input_scale);
  const Eigen::MatrixXd y = normalise(set.error_twists, n.output_mean, n.output_scale);
  const auto [search_x, search_y] = random_rows(x, y, rows, options.search.seed);
  const KernelHyperparameters start =
      initial != nullptr ? *initial : default_initial_hyperparameters(static_cast<int>(x.cols()));
  return maximise_likelihood(search_x, search_y, start, options.search);
}

double searched_log_likelihood(const TrainingSet& set, const TrainingOptions& options, int rows) {
  return search_on_rows(set, options, rows, nullptr).log_marginal_likelihood;
}

CableInputChoice choose_cable_inputs(const TrainingSet& set, const TrainingOptions& options,
                                     bool beyond_limit_elsewhere) {
  if (options.encoding != model::InputEncoding::bend_vector) {
    throw std::invalid_argument("the cables' residuals are offered beside the bend-vector encoding only");
  }
  CableInputChoice c;
  c.largest_residual_mm = set.cable_residuals.size() > 0 ? set.cable_residuals.cwiseAbs().maxCoeff() : 0.0;
  const int segments = static_cast<int>(set.bends.cols()) / 2;
  const int extra = static_cast<int>(set.inputs.cols()) - 2 * segments;
  const int with_residuals_inputs = static_cast<int>(set.bends.cols() + set.cable_residuals.cols()) + extra;
  if (with_residuals_inputs > model::kMaxInputs) {
    if (set.beyond_limit_rows > 0 || beyond_limit_elsewhere) {
      throw std::invalid_argument(fmt::format(
          "rows bend beyond the limit or the anchors' reach, and only the cable fit reads them, whose {} inputs "
          "exceed the board's {}",
          with_residuals_inputs, model::kMaxInputs));
    }
    c.reason = fmt::format("not offered: {} segments' residuals exceed the board's {} inputs", segments,
                           model::kMaxInputs);
    return c;
  }
  if (set.beyond_limit_rows > 0 || beyond_limit_elsewhere) {
    c.encoding = model::InputEncoding::bend_vector_cable_fit;
    c.reason = "rows bend beyond the limit or the anchors' reach: only the cable fit reads them on the board";
    return c;
  }
  if (!(c.largest_residual_mm > kConsistentResidualMm)) {
    c.reason = "the cables are consistent with constant curvature: the bend says everything they do";
    return c;
  }
  c.searched = true;
  c.search_rows = std::min(set.size(), std::max(2, options.sparse_search_rows));
  const TrainingSet with_residuals = with_encoding(set, model::InputEncoding::bend_vector_cable_fit);
  c.extra_parameters = options.search.isotropic ? 0 : static_cast<int>(set.cable_residuals.cols());
  c.bend_only_log_likelihood = searched_log_likelihood(set, options, c.search_rows);
  c.with_residuals_log_likelihood = searched_log_likelihood(with_residuals, options, c.search_rows);
  const double gain = c.with_residuals_log_likelihood - c.bend_only_log_likelihood - c.extra_parameters;
  if (gain > 0.0) {
    c.encoding = model::InputEncoding::bend_vector_cable_fit;
    c.reason = fmt::format("the cables' residuals raise the log likelihood by {:.1f} for {} length scales",
                           c.with_residuals_log_likelihood - c.bend_only_log_likelihood, c.extra_parameters);
  } else {
    c.reason = fmt::format("the cables' residuals raise the log likelihood by {:.1f}, not more than their {} "
                           "length scales",
                           c.with_residuals_log_likelihood - c.bend_only_log_likelihood, c.extra_parameters);
  }
  return c;
}

}  // namespace cdcr::training
