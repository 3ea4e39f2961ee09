#pragma once
// Training: normalise, search hyperparameters, fit, and package the result
// as a TrainedModel ready for export.

#include <vector>

#include <Eigen/Core>

#include "cdcr/model/geometry.hpp"
#include "cdcr/model/input_encoding.hpp"
#include "gaussian_process.hpp"
#include "hyperparameter_search.hpp"
#include "model_selection.hpp"
#include "trained_model/trained_model.hpp"
#include "training_set.hpp"

namespace cdcr::training {

// How the six outputs share hyperparameters.
//  * shared: one kernel for all six normalised outputs, one factorisation,
//    and the only form the flash image holds (one kernel row per query on the
//    board instead of six).
//  * per_output: six independent GPs; kept to measure what sharing costs.
enum class HyperparameterSharing { shared, per_output };

struct TrainingOptions {
  model::InputEncoding encoding = model::InputEncoding::bend_vector;
  HyperparameterSharing sharing = HyperparameterSharing::shared;
  SearchOptions search;
  // Exact or sparse, and M: see select_model().
  ModelChoice model = ModelChoice::automatic;
  int inducing_points = 0;
  BoardLimits board;
  // A sparse model's hyperparameters are those of the exact GP on at most
  // this many of its rows, drawn at random: the exact search costs O(N^3)
  // per evaluation, and a thousand rows pin the kernel's shape down.
  int sparse_search_rows = 1000;
  // Lloyd iterations that move the inducing inputs from their k-means++
  // seeds to the centres of the rows nearest each.
  int inducing_iterations = 10;
  // Points of the predictive-variance factor the image carries (0: none);
  // see predictive_variance.hpp.
  int variance_rank = 64;
  // A sequence's model may take where each cable last moved, where the
  // evidence says so (history_inputs.hpp); false keeps it out.
  bool offer_history = true;
};

struct TrainingReport {
  ModelSelection selection;
  double log_marginal_likelihood = 0.0;  // summed over outputs, normalised units; the search's rows
  int likelihood_evaluations = 0;
  int optimisations_completed = 0;
  int search_rows = 0;                   // rows the hyperparameter search saw
  double jitter = 0.0;
};

// Inputs and outputs are standardised per column before the GP sees them.
struct Normalisation {
  Eigen::VectorXd input_mean, input_scale;
  Vector6d output_mean, output_scale;
};

Normalisation normalisation_of(const TrainingSet& set);
Eigen::MatrixXd normalise(const Eigen::MatrixXd& m, const Eigen::VectorXd& mean, const Eigen::VectorXd& scale);

// A shared-hyperparameter model's kernel (the first output's variances).
KernelHyperparameters shared_hyperparameters(const TrainedModel& model);

// Shared hyperparameters only (throws std::invalid_argument otherwise). The
// model's kind and points follow select_model() for the rows of `set`.
TrainedModel train(const TrainingSet& set, const model::RobotGeometry<double>& geometry,
                   const TrainingOptions& options, TrainingReport* report = nullptr);

// The model fitted again on `set`, with the hyperparameters and the
// normalisation it has (they were found on other rows): a search finds the
// hyperparameters on the training rows, and once held-out rows have
// measured the result, the exported model is fitted on every row. An exact
// model gets one point per row of `set`; a sparse one keeps its inducing
// inputs and gets new weights.
TrainedModel refit(const TrainedModel& model, ModelKind kind, const TrainingSet& set);

// At most `count` rows of x and y, drawn at random without repetition (in
// their order): the rows a sparse model's hyperparameter search sees.
std::pair<Eigen::MatrixXd, Eigen::MatrixXd> random_rows(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y,
                                                        int count, std::uint64_t seed);

// M inducing inputs for normalised rows x: k-means++ seeds, then
// `iterations` of Lloyd's algorithm (a centre with no rows stays put).
Eigen::MatrixXd inducing_inputs(const Eigen::MatrixXd& x, int m, int iterations, std::uint64_t seed);

// Double-precision error twists (rows, (v, omega)) for stacked bend vectors
// and, for a model with the payload input, their payloads (throws
// std::invalid_argument when such a model gets none, or when the model takes
// the cables' residuals; a model without the input ignores them).
Eigen::MatrixXd predict_error_twists(const TrainedModel& model, const Eigen::MatrixXd& bends,
                                     const Eigen::VectorXd& payload_kg = {});

// The same for rows of a training set, with whatever inputs the model takes.
Eigen::MatrixXd predict_error_twists(const TrainedModel& model, const TrainingSet& rows);

// A fitted compensator of either sharing mode, for measurements that compare
// them; only the shared one can be exported.
struct Compensator {
  HyperparameterSharing sharing = HyperparameterSharing::shared;
  TrainedModel shared;
  // per_output: the normalisation is in `shared`, the six GPs here.
  std::vector<GaussianProcess> per_output;

  Eigen::MatrixXd predict(const TrainingSet& rows) const;
};

Compensator fit_compensator(const TrainingSet& set, const model::RobotGeometry<double>& geometry,
                            const TrainingOptions& options);

}  // namespace cdcr::training
