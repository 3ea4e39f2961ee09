#include "predictive_variance.hpp"

#include <algorithm>
#include <numeric>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Cholesky>

#include "cdcr/model/gp_uncertainty.hpp"
#include "gaussian_process.hpp"
#include "trainer.hpp"

namespace cdcr::training {

namespace {

// exp(-|a_i - b_j|^2 / 2): the trainer's kernel in kernel coordinates,
// where every length scale and the amplitude are 1.
Eigen::MatrixXd unit_kernel(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  KernelHyperparameters unit;
  unit.length_scales = Eigen::VectorXd::Ones(a.cols());
  unit.signal_variance = 1.0;
  return kernel_matrix(a, b, unit);
}

// The shared kernel's signal over noise; the image's variance block needs
// one kernel for every output.
double signal_to_noise(const TrainedModel& model) {
  if ((model.signal_variance.array() != model.signal_variance[0]).any() ||
      (model.noise_variance.array() != model.noise_variance[0]).any()) {
    throw std::invalid_argument("a variance factor needs one signal and one noise variance for every output");
  }
  return model.signal_variance[0] / model.noise_variance[0];
}

// a = L_u^-1 r and b = L_c^-1 a at each column's query (z's rows): the
// factor's two solves, column by column.
struct FactorSolves {
  Eigen::MatrixXd a, b;
};
FactorSolves factor_solves(const VarianceFactor& factor, const Eigen::MatrixXd& z) {
  FactorSolves s;
  s.a = factor.inducing_factor.triangularView<Eigen::Lower>().solve(unit_kernel(factor.points, z));
  s.b = factor.posterior_factor.triangularView<Eigen::Lower>().solve(s.a);
  return s;
}

// At most max_rows of rows 0..count-1, drawn at random (all of them, in
// order, when there are no more).
std::vector<int> sampled_rows(Eigen::Index count, int max_rows, std::uint64_t seed) {
  std::vector<int> rows(static_cast<std::size_t>(count));
  std::iota(rows.begin(), rows.end(), 0);
  if (count > max_rows) {
    std::mt19937_64 rng(seed);
    std::shuffle(rows.begin(), rows.end(), rng);
    rows.resize(static_cast<std::size_t>(max_rows));
  }
  return rows;
}

}  // namespace

Eigen::MatrixXd kernel_coordinates(const TrainedModel& model, const Eigen::MatrixXd& inputs) {
  const Eigen::VectorXd gain =
      (model.input_scale.array() * model.length_scales.array()).inverse().matrix();
  return (inputs.rowwise() - model.input_mean.transpose()).array().rowwise() * gain.transpose().array();
}

Eigen::MatrixXd variance_points(const TrainedModel& model, const Eigen::MatrixXd& fitted_inputs, int rank,
                                std::uint64_t seed) {
  const Eigen::MatrixXd z = kernel_coordinates(model, fitted_inputs);
  if (rank < 1 || rank > z.rows()) {
    throw std::invalid_argument("variance points must be between 1 and the number of fitted rows");
  }
  return inducing_inputs(z, rank, 10, seed);
}

VarianceFactor fit_variance_factor(const TrainedModel& model, const Eigen::MatrixXd& fitted_inputs,
                                   const Eigen::MatrixXd& points) {
  const double ratio = signal_to_noise(model);
  const Eigen::MatrixXd z = kernel_coordinates(model, fitted_inputs);
  const Eigen::Index r = points.rows();
  VarianceFactor f;
  f.points = points;
  // Variance points may come close together; jitter grows by decades until
  // R_uu factorises. It makes the board's variance slightly larger, never
  // smaller: the prior it approximates is the same.
  Eigen::MatrixXd r_uu = unit_kernel(points, points);
  Eigen::LLT<Eigen::MatrixXd> llt;
  for (double jitter = 1e-8;; jitter *= 10.0) {
    llt.compute(r_uu + jitter * Eigen::MatrixXd::Identity(r, r));
    if (llt.info() == Eigen::Success) {
      f.jitter = jitter;
      break;
    }
    if (jitter > 1e-2) throw std::runtime_error("variance points' kernel matrix is not positive definite");
  }
  f.inducing_factor = llt.matrixL();
  const Eigen::MatrixXd a = llt.matrixL().solve(unit_kernel(points, z));
  Eigen::MatrixXd c = Eigen::MatrixXd::Identity(r, r);
  c.selfadjointView<Eigen::Lower>().rankUpdate(a, ratio);
  Eigen::LLT<Eigen::MatrixXd> posterior(c.selfadjointView<Eigen::Lower>());
  if (posterior.info() != Eigen::Success) throw std::runtime_error("variance posterior factor failed");
  f.posterior_factor = posterior.matrixL();
  return f;
}

Eigen::VectorXd latent_share(const VarianceFactor& factor, const Eigen::MatrixXd& z) {
  const FactorSolves s = factor_solves(factor, z);
  const Eigen::VectorXd share = Eigen::VectorXd::Ones(z.rows()) - s.a.colwise().squaredNorm().transpose() +
                                s.b.colwise().squaredNorm().transpose();
  return share.cwiseMax(0.0).cwiseMin(1.0);
}

Eigen::VectorXd exact_latent_share(const TrainedModel& model, const Eigen::MatrixXd& fitted_inputs,
                                   const Eigen::MatrixXd& z) {
  const double ratio = signal_to_noise(model);
  const Eigen::MatrixXd x = kernel_coordinates(model, fitted_inputs);
  Eigen::MatrixXd k = unit_kernel(x, x);
  k.diagonal().array() += 1.0 / ratio;
  const Eigen::LLT<Eigen::MatrixXd> llt(k);
  if (llt.info() != Eigen::Success) throw std::runtime_error("exact kernel matrix does not factorise");
  const Eigen::MatrixXd r = unit_kernel(x, z);
  const Eigen::MatrixXd v = llt.matrixL().solve(r);
  return (Eigen::VectorXd::Ones(z.rows()) - v.colwise().squaredNorm().transpose()).cwiseMax(0.0);
}

Eigen::VectorXd held_out_latent_share(const TrainedModel& model, const Eigen::MatrixXd& rows) {
  const double ratio = signal_to_noise(model);
  const Eigen::MatrixXd z = kernel_coordinates(model, rows);
  const auto [a, b] = factor_solves(model.variance, z);
  Eigen::VectorXd share(z.rows());
  for (Eigen::Index i = 0; i < z.rows(); ++i) {
    const double q = b.col(i).squaredNorm();
    // C - (s/n) a_i a_i^T >= I, so 1 - (s/n) q > 0 in exact arithmetic; it
    // nears 0 only for a row the factor knows from itself alone, whose
    // share without it is the prior's.
    const double left = 1.0 - ratio * q;
    const double recovered = left > 1e-12 ? q / left : a.col(i).squaredNorm();
    share[i] = std::clamp(1.0 - a.col(i).squaredNorm() + recovered, 0.0, 1.0);
  }
  return share;
}

double extrapolation_threshold(const TrainedModel& model, const Eigen::MatrixXd& fitted_inputs, int max_rows,
                               std::uint64_t seed) {
  const std::vector<int> rows = sampled_rows(fitted_inputs.rows(), max_rows, seed);
  Eigen::VectorXd share = held_out_latent_share(model, fitted_inputs(rows, Eigen::all));
  std::sort(share.data(), share.data() + share.size());
  const double p99 = share[static_cast<Eigen::Index>(0.99 * static_cast<double>(share.size() - 1))];
  // Where the data leave much of the prior unknown (few variance points for
  // many inputs), twice would be the prior itself: then halfway from the
  // percentile to the prior. The image needs a positive threshold; a share
  // of 1e-6 is the float path's rounding, far below any data's.
  return std::clamp(std::min(2.0 * p99, 0.5 * (1.0 + p99)), 1e-6, 1.0);
}

RadiusCalibration calibrate_radii(const TrainedModel& model, const TrainingSet& set, double coverage, int max_rows,
                                  std::uint64_t seed) {
  const double ratio = signal_to_noise(model);
  const TrainingSet sample = set.subset(sampled_rows(set.size(), max_rows, seed));
  const Eigen::MatrixXd z = kernel_coordinates(model, sample.inputs);
  Eigen::MatrixXd k = unit_kernel(z, z);
  k.diagonal().array() += 1.0 / ratio;
  const Eigen::LLT<Eigen::MatrixXd> llt(k);
  if (llt.info() != Eigen::Success) throw std::runtime_error("exact kernel matrix does not factorise");
  // In units of the signal variance: (K + n I)^-1 = inverse / s.
  const Eigen::MatrixXd inverse = llt.solve(Eigen::MatrixXd::Identity(z.rows(), z.rows()));
  const Eigen::MatrixXd y = (sample.error_twists.rowwise() - model.output_mean.transpose()).array().rowwise() /
                            model.output_scale.transpose().array();
  const Eigen::MatrixXd alpha = inverse * y;
  // The radii are those the board computes, from the image's factor where
  // the model has one: the scales then correct the factor's approximation
  // too (with few variance points its variance is larger than the exact
  // GP's where the data are dense). The row is left out of the factor as of
  // the residual, so that a factor with a point at every row does not
  // shrink the radius there.
  const bool with_factor = model.variance.rank() > 0;
  const Eigen::VectorXd share = with_factor ? held_out_latent_share(model, sample.inputs) : Eigen::VectorXd();
  std::vector<double> position_ratio, orientation_ratio;
  for (Eigen::Index i = 0; i < z.rows(); ++i) {
    // Leave-one-out: residual alpha_i / [K^-1]_ii, variance 1 / [K^-1]_ii
    // (the noise included), both in normalised units.
    const double loo_variance = model.signal_variance[0] / inverse(i, i);
    const double variance = with_factor ? model.signal_variance[0] * share[i] + model.noise_variance[0] : loo_variance;
    double variances[model::kImageOutputs];
    Vector6d residual;
    for (int c = 0; c < model::kImageOutputs; ++c) {
      residual[c] = model.output_scale[c] * alpha(i, c) / inverse(i, i);
      variances[c] = model.output_scale[c] * model.output_scale[c] * variance;
    }
    const Eigen::Vector3d tip = sample.measured[static_cast<std::size_t>(i)].position_mm;
    double r_mm = 0.0;
    double r_deg = 0.0;
    model::gaussian_radii_95(variances, tip, r_mm, r_deg);
    const Eigen::Vector3d omega = residual.tail<3>();
    const Eigen::Vector3d position_error = residual.head<3>() + omega.cross(tip);
    position_ratio.push_back(position_error.norm() / r_mm);
    orientation_ratio.push_back(omega.norm() * model::kDegreesPerRadian / r_deg);
  }
  const auto quantile = [coverage](std::vector<double>& v) {
    const auto at = static_cast<std::size_t>(std::ceil(coverage * static_cast<double>(v.size()))) - 1;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(at), v.end());
    return v[at];
  };
  RadiusCalibration c;
  c.rows = static_cast<int>(z.rows());
  c.position_scale = quantile(position_ratio);
  c.orientation_scale = quantile(orientation_ratio);
  return c;
}

}  // namespace cdcr::training
