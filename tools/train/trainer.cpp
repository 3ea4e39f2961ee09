#include "trainer.hpp"

#include <algorithm>
#include <numeric>
#include <random>
#include <stdexcept>

#include "cdcr/firmware/compensated_pose.hpp"
#include "sparse_gp.hpp"

namespace cdcr::training {

namespace {

// A constant column (a segment never bent in the data) gets scale 1 so the
// normalised value is simply zero.
Eigen::VectorXd column_scale(const Eigen::MatrixXd& m, const Eigen::VectorXd& mean) {
  Eigen::VectorXd scale = ((m.rowwise() - mean.transpose()).array().square().colwise().mean().sqrt()).transpose();
  for (Eigen::Index i = 0; i < scale.size(); ++i) {
    if (!(scale[i] > 1e-12)) scale[i] = 1.0;
  }
  return scale;
}

TrainedModel packaged(const TrainingSet& set, const model::RobotGeometry<double>& geometry,
                      const TrainingOptions& options, const Normalisation& n) {
  TrainedModel m;
  m.encoding = options.encoding;
  m.geometry = geometry;
  m.input_mean = n.input_mean;
  m.input_scale = n.input_scale;
  m.output_mean = n.output_mean;
  m.output_scale = n.output_scale;
  m.inputs = set.inputs;
  m.set_input_range(set.inputs);
  if (set.has_payload()) m.default_payload_kg = set.payload_kg.mean();
  return m;
}

}  // namespace

Normalisation normalisation_of(const TrainingSet& set) {
  if (set.size() < 2) throw std::invalid_argument("training needs at least two samples");
  Normalisation n;
  n.input_mean = set.inputs.colwise().mean().transpose();
  n.input_scale = column_scale(set.inputs, n.input_mean);
  // The board reads the cables in the protocol's steps: a residual that
  // varies by less over the rows is rounding, and normalised by its own
  // spread would turn the board's rounding into large kernel coordinates.
  if (model::takes_cable_residuals(set.encoding)) {
    for (Eigen::Index c = set.bends.cols(); c < set.bends.cols() + set.cable_residuals.cols(); ++c) {
      n.input_scale[c] = std::max(n.input_scale[c], double(firmware::kCableResolutionMm));
    }
  }
  n.output_mean = set.error_twists.colwise().mean().transpose();
  n.output_scale = column_scale(set.error_twists, n.output_mean);
  return n;
}

Eigen::MatrixXd normalise(const Eigen::MatrixXd& m, const Eigen::VectorXd& mean, const Eigen::VectorXd& scale) {
  return (m.rowwise() - mean.transpose()).array().rowwise() / scale.transpose().array();
}

KernelHyperparameters shared_hyperparameters(const TrainedModel& model) {
  KernelHyperparameters h;
  h.length_scales = model.length_scales;
  h.signal_variance = model.signal_variance[0];
  h.noise_variance = model.noise_variance[0];
  return h;
}

namespace {

// Normalised rows back to the model's input units, the way the image
// stores its points.
Eigen::MatrixXd denormalised(const Eigen::MatrixXd& m, const Eigen::VectorXd& mean, const Eigen::VectorXd& scale) {
  return (m.array().rowwise() * scale.transpose().array()).rowwise() + mean.transpose().array();
}

}  // namespace

std::pair<Eigen::MatrixXd, Eigen::MatrixXd> random_rows(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y,
                                                        int count, std::uint64_t seed) {
  if (count >= x.rows()) return {x, y};
  std::vector<int> order(static_cast<std::size_t>(x.rows()));
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 rng(seed);
  std::shuffle(order.begin(), order.end(), rng);
  order.resize(static_cast<std::size_t>(count));
  std::sort(order.begin(), order.end());
  return {x(order, Eigen::all), y(order, Eigen::all)};
}

Eigen::MatrixXd inducing_inputs(const Eigen::MatrixXd& x, int m, int iterations, std::uint64_t seed) {
  Eigen::MatrixXd z = initial_inducing_inputs(x, m, seed);
  for (int iteration = 0; iteration < iterations; ++iteration) {
    // Squared distances less each row's own |x|^2, which does not change
    // which centre is nearest.
    Eigen::MatrixXd distance = -2.0 * x * z.transpose();
    distance.rowwise() += z.rowwise().squaredNorm().transpose();
    Eigen::MatrixXd sums = Eigen::MatrixXd::Zero(m, x.cols());
    Eigen::VectorXi counts = Eigen::VectorXi::Zero(m);
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      Eigen::Index nearest = 0;
      distance.row(i).minCoeff(&nearest);
      sums.row(nearest) += x.row(i);
      ++counts[nearest];
    }
    for (int k = 0; k < m; ++k) {
      if (counts[k] > 0) z.row(k) = sums.row(k) / counts[k];
    }
  }
  return z;
}

TrainedModel train(const TrainingSet& set, const model::RobotGeometry<double>& geometry,
                   const TrainingOptions& options, TrainingReport* report) {
  if (options.sharing != HyperparameterSharing::shared) {
    throw std::invalid_argument("only shared hyperparameters can be exported to a flash image");
  }
  const Normalisation n = normalisation_of(set);
  const ModelSelection selection =
      select_model(set.size(), static_cast<int>(set.inputs.cols()), geometry.segment_count, options.model,
                   options.inducing_points, options.board);
  const Eigen::MatrixXd x = normalise(set.inputs, n.input_mean, n.input_scale);
  const Eigen::MatrixXd y = normalise(set.error_twists, n.output_mean, n.output_scale);
  const int search_rows = selection.kind == ModelKind::exact
                              ? set.size()
                              : std::min(set.size(), std::max(2, options.sparse_search_rows));
  const auto [search_x, search_y] = random_rows(x, y, search_rows, options.search.seed);
  const SearchResult search = maximise_likelihood(
      search_x, search_y, default_initial_hyperparameters(static_cast<int>(x.cols())), options.search);

  TrainedModel m = packaged(set, geometry, options, n);
  m.fitted_rows = static_cast<std::uint32_t>(set.size());
  m.length_scales = search.hyperparameters.length_scales;
  m.signal_variance.setConstant(search.hyperparameters.signal_variance);
  m.noise_variance.setConstant(search.hyperparameters.noise_variance);
  double jitter = 0.0;
  if (selection.kind == ModelKind::exact) {
    const GaussianProcess gp = GaussianProcess::fit(x, y, search.hyperparameters);
    m.alpha = gp.alpha;
    jitter = gp.jitter;
  } else {
    SparseParameters p;
    p.hyperparameters = search.hyperparameters;
    p.inducing = inducing_inputs(x, selection.points, options.inducing_iterations, options.search.seed);
    const SparseGaussianProcess gp = SparseGaussianProcess::fit(x, y, p);
    m.kind = model::ImageModelKind::sparse_gp;
    m.inputs = denormalised(p.inducing, n.input_mean, n.input_scale);
    m.alpha = gp.beta;
  }
  if (report != nullptr) {
    report->selection = selection;
    report->log_marginal_likelihood = search.log_marginal_likelihood;
    report->likelihood_evaluations = search.likelihood_evaluations;
    report->optimisations_completed = search.optimisations_completed;
    report->search_rows = search_rows;
    report->jitter = jitter;
  }
  return m;
}

TrainedModel refit(const TrainedModel& model, ModelKind kind, const TrainingSet& set) {
  if (set.size() < 2) throw std::invalid_argument("training needs at least two samples");
  const KernelHyperparameters h = shared_hyperparameters(model);
  const Eigen::MatrixXd x = normalise(set.inputs, model.input_mean, model.input_scale);
  const Eigen::MatrixXd y = normalise(set.error_twists, model.output_mean, model.output_scale);
  TrainedModel refitted = model;
  refitted.set_input_range(set.inputs);
  if (set.has_payload()) refitted.default_payload_kg = set.payload_kg.mean();
  refitted.fitted_rows = static_cast<std::uint32_t>(set.size());
  if (kind == ModelKind::exact) {
    refitted.kind = model::ImageModelKind::exact_gp;
    refitted.inputs = set.inputs;
    refitted.alpha = GaussianProcess::fit(x, y, h).alpha;
  } else {
    refitted.kind = model::ImageModelKind::sparse_gp;
    SparseParameters p;
    p.hyperparameters = h;
    p.inducing = normalise(model.inputs, model.input_mean, model.input_scale);
    refitted.alpha = SparseGaussianProcess::fit(x, y, p).beta;
  }
  return refitted;
}

namespace {
// The model's inputs for these rows: the cable residuals and the payload
// only if the model takes them.
Eigen::MatrixXd inputs_for(const TrainedModel& model, const Eigen::MatrixXd& bends,
                           const Eigen::MatrixXd& cable_residuals, const Eigen::MatrixXd& history_inputs,
                           const Eigen::VectorXd& payload_kg) {
  if (model.has_payload_input() && payload_kg.size() == 0) {
    throw std::invalid_argument("the model takes a payload input and the rows have none");
  }
  if (model::takes_cable_residuals(model.encoding) && cable_residuals.rows() != bends.rows()) {
    throw std::invalid_argument("the model takes the cables' residuals and the rows have none");
  }
  if (model::takes_history(model.encoding) && history_inputs.rows() != bends.rows()) {
    throw std::invalid_argument("the model takes the cables' history and the rows have none");
  }
  return model_inputs(bends, cable_residuals, history_inputs,
                      model.has_payload_input() ? payload_kg : Eigen::VectorXd(), model.encoding);
}

Eigen::MatrixXd predict_at(const TrainedModel& model, const Eigen::MatrixXd& inputs) {
  const Eigen::MatrixXd x = normalise(inputs, model.input_mean, model.input_scale);
  const Eigen::MatrixXd train_x = normalise(model.inputs, model.input_mean, model.input_scale);
  Eigen::MatrixXd y(x.rows(), 6);
  for (int k = 0; k < 6; ++k) {
    KernelHyperparameters h;
    h.length_scales = model.length_scales;
    h.signal_variance = model.signal_variance[k];
    h.noise_variance = model.noise_variance[k];
    y.col(k) = kernel_matrix(x, train_x, h) * model.alpha.col(k);
  }
  return (y.array().rowwise() * model.output_scale.transpose().array()).rowwise() + model.output_mean.transpose().array();
}
}  // namespace

Eigen::MatrixXd predict_error_twists(const TrainedModel& model, const Eigen::MatrixXd& bends,
                                     const Eigen::VectorXd& payload_kg) {
  return predict_at(model, inputs_for(model, bends, Eigen::MatrixXd(), Eigen::MatrixXd(), payload_kg));
}

Eigen::MatrixXd predict_error_twists(const TrainedModel& model, const TrainingSet& rows) {
  return predict_at(model,
                    inputs_for(model, rows.bends, rows.cable_residuals, rows.history_inputs, rows.payload_kg));
}

Compensator fit_compensator(const TrainingSet& set, const model::RobotGeometry<double>& geometry,
                            const TrainingOptions& options) {
  Compensator c;
  c.sharing = options.sharing;
  if (options.sharing == HyperparameterSharing::shared) {
    c.shared = train(set, geometry, options);
    return c;
  }
  const Normalisation n = normalisation_of(set);
  c.shared = packaged(set, geometry, options, n);
  const Eigen::MatrixXd x = normalise(set.inputs, n.input_mean, n.input_scale);
  const Eigen::MatrixXd y = normalise(set.error_twists, n.output_mean, n.output_scale);
  for (int k = 0; k < 6; ++k) {
    const Eigen::MatrixXd yk = y.col(k);
    const SearchResult search =
        maximise_likelihood(x, yk, default_initial_hyperparameters(static_cast<int>(x.cols())), options.search);
    c.per_output.push_back(GaussianProcess::fit(x, yk, search.hyperparameters));
  }
  return c;
}

Eigen::MatrixXd Compensator::predict(const TrainingSet& rows) const {
  if (sharing == HyperparameterSharing::shared) return predict_error_twists(shared, rows);
  const Eigen::MatrixXd x =
      normalise(inputs_for(shared, rows.bends, rows.cable_residuals, rows.history_inputs, rows.payload_kg),
                shared.input_mean,
                shared.input_scale);
  Eigen::MatrixXd y(x.rows(), 6);
  for (int k = 0; k < 6; ++k) y.col(k) = per_output[k].predict(x);
  return (y.array().rowwise() * shared.output_scale.transpose().array()).rowwise() +
         shared.output_mean.transpose().array();
}

}  // namespace cdcr::training
