#pragma once
// Whether the GP takes what the cables say beyond the bend (the cable fit's
// residuals, model/cable_fit.hpp), by evidence, as the other choices: the
// hyperparameter search's log marginal likelihood on the same rows with and
// without them, less one per extra length scale (Akaike's criterion).
//
// Rows whose cables are exactly consistent with constant curvature carry
// nothing there: without a residual above kConsistentResidualMm the choice
// is not searched, and the model is today's. Rows beyond the bend limit or
// the anchors' reach leave no choice: only the cable fit reads them on the
// board.

#include <string>

#include "cdcr/model/input_encoding.hpp"
#include "trainer.hpp"
#include "training_set.hpp"

namespace cdcr::training {

// Residuals below this are rounding of consistent lengths (a float32
// length of a metre is good to 0.06 um).
inline constexpr double kConsistentResidualMm = 1e-4;

struct CableInputChoice {
  model::InputEncoding encoding = model::InputEncoding::bend_vector;
  bool searched = false;  // both candidates' likelihoods were searched
  double bend_only_log_likelihood = 0.0;
  double with_residuals_log_likelihood = 0.0;
  int extra_parameters = 0;  // the residuals' length scales
  int search_rows = 0;
  double largest_residual_mm = 0.0;
  std::string reason;  // one line
};

// The hyperparameter search's optimum (log marginal likelihood, normalised
// units) on `rows` of the set's rows drawn at random with the search's seed:
// the same rows for two sets of the same size, whatever their inputs.
double searched_log_likelihood(const TrainingSet& set, const TrainingOptions& options, int rows);
// The same search from `initial` (null: the default start), whole.
SearchResult search_on_rows(const TrainingSet& set, const TrainingOptions& options, int rows,
                            const KernelHyperparameters* initial);

// `set` holds the training rows in the bend-vector encoding; options as the
// trainer's (the search, its rows and seed). beyond_limit_elsewhere: rows the
// model must read that `set` does not hold (held-out ones) bend beyond the
// limit.
CableInputChoice choose_cable_inputs(const TrainingSet& set, const TrainingOptions& options,
                                     bool beyond_limit_elsewhere = false);

}  // namespace cdcr::training
