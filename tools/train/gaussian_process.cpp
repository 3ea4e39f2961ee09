#include "gaussian_process.hpp"

#include <cmath>
#include <stdexcept>

#include "lapack.hpp"

namespace cdcr::training {

namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

Eigen::VectorXd KernelHyperparameters::to_log() const {
  const Eigen::Index d = length_scales.size();
  Eigen::VectorXd p(d + 2);
  p.head(d) = length_scales.array().log().matrix();
  p[d] = std::log(signal_variance);
  p[d + 1] = std::log(noise_variance);
  return p;
}

KernelHyperparameters KernelHyperparameters::from_log(const Eigen::VectorXd& log_parameters) {
  const Eigen::Index d = log_parameters.size() - 2;
  KernelHyperparameters h;
  h.length_scales = log_parameters.head(d).array().exp().matrix();
  h.signal_variance = std::exp(log_parameters[d]);
  h.noise_variance = std::exp(log_parameters[d + 1]);
  return h;
}

Eigen::MatrixXd kernel_matrix(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const KernelHyperparameters& h) {
  const Eigen::RowVectorXd inverse_scale = h.length_scales.cwiseInverse().transpose();
  const Eigen::MatrixXd as = a.array().rowwise() * inverse_scale.array();
  const Eigen::MatrixXd bs = b.array().rowwise() * inverse_scale.array();
  // |a_i - b_j|^2 = |a_i|^2 + |b_j|^2 - 2 a_i.b_j, clamped against rounding below zero.
  Eigen::MatrixXd distance_sq = -2.0 * as * bs.transpose();
  distance_sq.colwise() += as.rowwise().squaredNorm();
  distance_sq.rowwise() += bs.rowwise().squaredNorm().transpose();
  return h.signal_variance * (-0.5 * distance_sq.cwiseMax(0.0)).array().exp().matrix();
}

Eigen::MatrixXd gram_matrix(const Eigen::MatrixXd& x, const KernelHyperparameters& h) {
  Eigen::MatrixXd k = kernel_matrix(x, x, h);
  k = 0.5 * (k + k.transpose()).eval();
  k.diagonal().setConstant(h.signal_variance);
  return k;
}

namespace {

// The lower triangle of the kernel matrix of the scaled inputs a (N x D)
// with themselves, straight from the differences (no cancellation, never
// below zero); the diagonal is exactly the signal variance. The strict
// upper triangle is left alone: every user reads the lower one only.
void lower_gram(const Eigen::MatrixXd& a, double signal_variance, Eigen::MatrixXd& k) {
  const Eigen::Index n = a.rows();
  const Eigen::Index d = a.cols();
  k.resize(n, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const Eigen::Index below = n - j - 1;
    auto column = k.col(j).tail(below);
    column.setZero();
    for (Eigen::Index c = 0; c < d; ++c) {
      column.array() += (a.col(c).tail(below).array() - a(j, c)).square();
    }
    column = signal_variance * (-0.5 * column.array()).exp();
    k(j, j) = signal_variance;
  }
}

// The lower Cholesky factor of K_signal + noise I (lower triangles) into l,
// with jitter growing by decades from 1e-10 of the signal variance until
// the factorisation succeeds; returns the jitter.
double factorise(const Eigen::MatrixXd& k_signal, double noise_variance, double signal_variance,
                 Eigen::MatrixXd& l) {
  l.resize(k_signal.rows(), k_signal.cols());
  l.triangularView<Eigen::Lower>() = k_signal;
  l.diagonal().array() += noise_variance;
  double jitter = 1e-10 * signal_variance;
  double added = 0.0;
  while (lapack::cholesky_lower(l) != 0) {
    if (jitter > 1e-2 * signal_variance) {
      throw std::runtime_error("kernel matrix is not positive definite even with jitter");
    }
    l.triangularView<Eigen::Lower>() = k_signal;
    l.diagonal().array() += noise_variance + jitter;
    added = jitter;
    jitter *= 10.0;
  }
  return added;
}

void scale_inputs(const Eigen::MatrixXd& x, const KernelHyperparameters& h, Eigen::MatrixXd& a) {
  a = x.array().rowwise() * h.length_scales.cwiseInverse().transpose().array();
}

}  // namespace

LikelihoodResult log_marginal_likelihood(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y,
                                         const KernelHyperparameters& h, bool with_gradient) {
  LikelihoodWorkspace workspace;
  return log_marginal_likelihood(x, y, h, with_gradient, workspace);
}

LikelihoodResult log_marginal_likelihood(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y,
                                         const KernelHyperparameters& h, bool with_gradient,
                                         LikelihoodWorkspace& workspace) {
  const Eigen::Index n = x.rows();
  const Eigen::Index d = x.cols();
  const double outputs = static_cast<double>(y.cols());
  Eigen::MatrixXd& a = workspace.scaled_inputs;
  Eigen::MatrixXd& k_signal = workspace.k_signal;
  Eigen::MatrixXd& factor = workspace.factor;
  Eigen::MatrixXd& alpha = workspace.alpha;
  scale_inputs(x, h, a);
  lower_gram(a, h.signal_variance, k_signal);
  LikelihoodResult result;
  result.jitter = factorise(k_signal, h.noise_variance, h.signal_variance, factor);
  alpha = y;
  lapack::cholesky_solve_lower(factor, alpha);

  const double log_det = 2.0 * factor.diagonal().array().log().sum();
  result.log_marginal_likelihood = -0.5 * (y.array() * alpha.array()).sum() - 0.5 * outputs * log_det -
                                   0.5 * outputs * static_cast<double>(n) * std::log(2.0 * kPi);
  if (!with_gradient) return result;

  // dLML/dp = 1/2 tr(W dK/dp), W = alpha alpha^T - m K^-1 (symmetric).
  // K^-1 from the factor (potri: triangular inverse, then the lower
  // triangle of L^-T L^-1; 2n^3/3 flops, the dominant cost).
  Eigen::MatrixXd& k_inverse = factor;
  if (lapack::inverse_from_cholesky_lower(k_inverse) != 0) {
    throw std::runtime_error("kernel matrix inverse failed");
  }

  // One pass over the strict lower triangle, column by column, with
  // M = W .* K_signal:
  //   signal:  1/2 sum_ij M_ij                    = 1/2 diag + sum_{i>j} M_ij
  //   scale d: 1/2 sum_ij M_ij (a_id - a_jd)^2   = sum_{i>j} M_ij (a_id - a_jd)^2
  //   noise:   1/2 noise tr(W)
  // The diagonal of M is (|alpha_i|^2 - m K^-1_ii) signal_variance.
  const double w_trace = alpha.squaredNorm() - outputs * k_inverse.diagonal().sum();
  double signal_sum = 0.0;
  Eigen::VectorXd scale_sums = Eigen::VectorXd::Zero(d);
  workspace.column.resize(n);
  for (Eigen::Index j = 0; j + 1 < n; ++j) {
    const Eigen::Index below = n - j - 1;
    auto m = workspace.column.head(below);
    m.noalias() = alpha.bottomRows(below) * alpha.row(j).transpose();
    m = (m - outputs * k_inverse.col(j).tail(below)).cwiseProduct(k_signal.col(j).tail(below));
    signal_sum += m.sum();
    for (Eigen::Index c = 0; c < d; ++c) {
      scale_sums[c] += (m.array() * (a.col(c).tail(below).array() - a(j, c)).square()).sum();
    }
  }
  result.gradient.resize(d + 2);
  result.gradient.head(d) = scale_sums;
  result.gradient[d] = signal_sum + 0.5 * h.signal_variance * w_trace;
  result.gradient[d + 1] = 0.5 * h.noise_variance * w_trace;
  return result;
}

GaussianProcess GaussianProcess::fit(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y,
                                     const KernelHyperparameters& h) {
  Eigen::MatrixXd a;
  Eigen::MatrixXd k_signal;
  Eigen::MatrixXd factor;
  scale_inputs(x, h, a);
  lower_gram(a, h.signal_variance, k_signal);
  GaussianProcess gp;
  gp.hyperparameters = h;
  gp.inputs = x;
  gp.jitter = factorise(k_signal, h.noise_variance, h.signal_variance, factor);
  gp.alpha = y;
  lapack::cholesky_solve_lower(factor, gp.alpha);
  return gp;
}

Eigen::MatrixXd GaussianProcess::predict(const Eigen::MatrixXd& queries) const {
  return kernel_matrix(queries, inputs, hyperparameters) * alpha;
}

}  // namespace cdcr::training
