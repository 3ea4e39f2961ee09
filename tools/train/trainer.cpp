#include "trainer.hpp"

#include <stdexcept>

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
  return m;
}

}  // namespace

Normalisation normalisation_of(const TrainingSet& set) {
  if (set.size() < 2) throw std::invalid_argument("training needs at least two samples");
  Normalisation n;
  n.input_mean = set.inputs.colwise().mean().transpose();
  n.input_scale = column_scale(set.inputs, n.input_mean);
  n.output_mean = set.error_twists.colwise().mean().transpose();
  n.output_scale = column_scale(set.error_twists, n.output_mean);
  return n;
}

Eigen::MatrixXd normalise(const Eigen::MatrixXd& m, const Eigen::VectorXd& mean, const Eigen::VectorXd& scale) {
  return (m.rowwise() - mean.transpose()).array().rowwise() / scale.transpose().array();
}

TrainedModel train(const TrainingSet& set, const model::RobotGeometry<double>& geometry,
                   const TrainingOptions& options, TrainingReport* report) {
  if (options.sharing != HyperparameterSharing::shared) {
    throw std::invalid_argument("only shared hyperparameters can be exported to a flash image");
  }
  const Normalisation n = normalisation_of(set);
  const Eigen::MatrixXd x = normalise(set.inputs, n.input_mean, n.input_scale);
  const Eigen::MatrixXd y = normalise(set.error_twists, n.output_mean, n.output_scale);
  const SearchResult search =
      maximise_likelihood(x, y, default_initial_hyperparameters(static_cast<int>(x.cols())), options.search);
  const GaussianProcess gp = GaussianProcess::fit(x, y, search.hyperparameters);

  TrainedModel m = packaged(set, geometry, options, n);
  m.length_scales = search.hyperparameters.length_scales;
  m.signal_variance.setConstant(search.hyperparameters.signal_variance);
  m.noise_variance.setConstant(search.hyperparameters.noise_variance);
  m.alpha = gp.alpha;
  if (report != nullptr) {
    report->log_marginal_likelihood = search.log_marginal_likelihood;
    report->likelihood_evaluations = search.likelihood_evaluations;
    report->optimisations_completed = search.optimisations_completed;
    report->jitter = gp.jitter;
  }
  return m;
}

TrainedModel refit(const TrainedModel& model, const TrainingSet& set) {
  if (set.size() < 2) throw std::invalid_argument("training needs at least two samples");
  KernelHyperparameters h;
  h.length_scales = model.length_scales;
  h.signal_variance = model.signal_variance[0];
  h.noise_variance = model.noise_variance[0];
  const Eigen::MatrixXd x = normalise(set.inputs, model.input_mean, model.input_scale);
  const Eigen::MatrixXd y = normalise(set.error_twists, model.output_mean, model.output_scale);
  TrainedModel refitted = model;
  refitted.inputs = set.inputs;
  refitted.set_input_range(set.inputs);
  refitted.alpha = GaussianProcess::fit(x, y, h).alpha;
  return refitted;
}

Eigen::MatrixXd predict_error_twists(const TrainedModel& model, const Eigen::MatrixXd& bends) {
  const Eigen::MatrixXd x = normalise(encode_rows(bends, model.encoding), model.input_mean, model.input_scale);
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

Eigen::MatrixXd Compensator::predict(const Eigen::MatrixXd& bends) const {
  if (sharing == HyperparameterSharing::shared) return predict_error_twists(shared, bends);
  const Eigen::MatrixXd x = normalise(encode_rows(bends, shared.encoding), shared.input_mean, shared.input_scale);
  Eigen::MatrixXd y(x.rows(), 6);
  for (int k = 0; k < 6; ++k) y.col(k) = per_output[k].predict(x);
  return (y.array().rowwise() * shared.output_scale.transpose().array()).rowwise() +
         shared.output_mean.transpose().array();
}

}  // namespace cdcr::training
