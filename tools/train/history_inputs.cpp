#include "history_inputs.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "cable_inputs.hpp"
#include "cdcr/model/input_encoding.hpp"
#include "cdcr/model/limits.hpp"
#include "hysteresis_identification.hpp"

namespace cdcr::training {

namespace {
// The history's length scales where the warm start puts them (normalised
// inputs): so long that the start is the model without the history (two
// opposite directions 2/30 apart), from where the search shortens those the
// data ask for. (At 3, the start's kernel was another one and the search
// ended 40 below the model without the history on a real-like run.)
constexpr double kWarmHistoryLengthScale = 30.0;
}  // namespace

model::HysteresisModel<double> with_history_operator(const model::HysteresisModel<double>& hysteresis,
                                                     double width_mm, const model::RobotGeometry<double>& geometry) {
  if (hysteresis.operators >= model::kMaxHysteresisOperators) {
    throw std::invalid_argument(
        fmt::format("the cables have {} play operators, the board's most", hysteresis.operators));
  }
  if (!(width_mm > 0.0) || !(width_mm <= model::kMaxHysteresisWidthMm)) {
    throw std::invalid_argument(fmt::format("a history width of {} mm is outside (0, {}] mm", width_mm,
                                            model::kMaxHysteresisWidthMm));
  }
  model::HysteresisModel<double> m = hysteresis;
  if (m.empty()) m.cables = geometry.cable_count();
  const int k = m.operators;
  m.operators = k + 1;
  for (int c = 0; c < m.cables; ++c) {
    m.widths_mm[c][k] = width_mm;
    m.weights[c][k] = 0.0;
  }
  // The homing lags of the others stay as identified.
  model::HysteresisModel<double> homed = m;
  model::CableVector<double> approach_mm, home_mm;
  if (const model::Status s = model::homing_waypoints(geometry, approach_mm, home_mm); s != model::Status::ok) {
    throw std::invalid_argument(std::string("homing move: ") + model::to_string(s));
  }
  model::compute_homing_lags(homed, approach_mm, home_mm);
  for (int c = 0; c < m.cables; ++c) m.homing_lag_mm[c][k] = homed.homing_lag_mm[c][k];
  return m;
}

HistoryChoice choose_history_inputs(const dataset::Dataset& data, const std::vector<int>& train_rows,
                                    const model::HysteresisModel<double>& hysteresis,
                                    const model::RobotGeometry<double>& geometry, const TrainingOptions& options,
                                    bool with_payload) {
  HistoryChoice c;
  c.model = hysteresis;
  const int segments = geometry.segment_count;
  const model::InputEncoding with = model::with_history(options.encoding, true);
  const int extra = with_payload && data.has_payload ? 1 : 0;
  if (!model::takes_history(with)) {
    c.reason = fmt::format("not offered with the {} encoding", model::to_string(options.encoding));
    return c;
  }
  if (model::encoded_input_count(with, geometry) + extra > model::kMaxInputs) {
    c.reason = fmt::format("not offered: {} segments' history inputs exceed the board's {} inputs", segments,
                           model::kMaxInputs);
    return c;
  }
  if (hysteresis.operators >= model::kMaxHysteresisOperators) {
    c.reason = "not offered: the cables have no play operator to spare";
    return c;
  }
  if (static_cast<int>(train_rows.size()) < kMinHysteresisRows) {
    c.reason = fmt::format("not offered: {} training rows, fewer than {}", train_rows.size(), kMinHysteresisRows);
    return c;
  }
  c.searched = true;
  const TrainingSet without = make_sequence_training_set(data, hysteresis, geometry, options.encoding, with_payload)
                                  .subset(train_rows);
  c.search_rows = std::min(without.size(), std::max(2, options.sparse_search_rows));
  c.extra_parameters = (options.search.isotropic ? 0 : geometry.cable_count()) + 1;
  const SearchResult without_search = search_on_rows(without, options, c.search_rows, nullptr);
  c.without_log_likelihood = without_search.log_marginal_likelihood;
  // Each candidate's search also starts where the model without the history
  // ended, the history's length scales long (it then starts near the model
  // without it, and ends no lower unless the search fails).
  KernelHyperparameters warm = without_search.hyperparameters;
  const Eigen::Index without_dims = warm.length_scales.size();
  const int history_dims = geometry.cable_count();
  const bool warm_start = !options.search.isotropic && without_dims >= extra;
  if (warm_start) {
    Eigen::VectorXd scales(without_dims + history_dims);
    // The history columns sit before the payload, when there is one.
    const Eigen::Index before = without_dims - extra;
    scales << warm.length_scales.head(before), Eigen::VectorXd::Constant(history_dims, kWarmHistoryLengthScale),
        warm.length_scales.tail(extra);
    warm.length_scales = scales;
  }
  // A candidate must beat the model without it by more than its penalty.
  c.penalty = 0.5 * std::log(static_cast<double>(c.search_rows)) * c.extra_parameters;
  double to_beat = c.without_log_likelihood + c.penalty;
  double best_log_likelihood = -std::numeric_limits<double>::infinity();
  for (const double width : kHistoryWidthsMm) {
    const model::HysteresisModel<double> candidate = with_history_operator(hysteresis, width, geometry);
    const TrainingSet set =
        make_sequence_training_set(data, candidate, geometry, with, with_payload).subset(train_rows);
    double lml = search_on_rows(set, options, c.search_rows, nullptr).log_marginal_likelihood;
    if (warm_start) lml = std::max(lml, search_on_rows(set, options, c.search_rows, &warm).log_marginal_likelihood);
    c.candidates.push_back({width, lml});
    best_log_likelihood = std::max(best_log_likelihood, lml);
    if (lml > to_beat) {
      to_beat = lml;
      c.chosen = true;
      c.width_mm = width;
      c.model = candidate;
    }
  }
  const double gain = best_log_likelihood - c.without_log_likelihood;
  c.reason = c.chosen ? fmt::format("where each cable last moved (width {} mm) raises the log likelihood by {:.1f} "
                                    "for {} parameters ({:.1f} needed)",
                                    c.width_mm, gain, c.extra_parameters, c.penalty)
                      : fmt::format("where each cable last moved raises the log likelihood by {:.1f} at best, less "
                                    "than the {:.1f} its {} parameters need",
                                    gain, c.penalty, c.extra_parameters);
  return c;
}

}  // namespace cdcr::training
