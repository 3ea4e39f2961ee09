#include "gaussian_process.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/Cholesky>

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

// In-place inverse of a lower-triangular matrix by recursive halving:
// inv([A 0; B C]) = [inv(A) 0; -inv(C) B inv(A)  inv(C)]. The off-diagonal
// block is two triangular products, so the whole costs n^3/3 flops where a
// triangular solve against the identity costs n^3.
void invert_lower_triangular(Eigen::Ref<Eigen::MatrixXd> l) {
  const Eigen::Index n = l.rows();
  constexpr Eigen::Index kDirect = 64;
  if (n <= kDirect) {
    Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(n, n);
    l.triangularView<Eigen::Lower>().solveInPlace(identity);
    l = identity;
    return;
  }
  const Eigen::Index n1 = n / 2;
  const Eigen::Index n2 = n - n1;
  invert_lower_triangular(l.topLeftCorner(n1, n1));
  invert_lower_triangular(l.bottomRightCorner(n2, n2));
  Eigen::MatrixXd b = l.bottomLeftCorner(n2, n1) * l.topLeftCorner(n1, n1).triangularView<Eigen::Lower>();
  l.bottomLeftCorner(n2, n1).noalias() = -(l.bottomRightCorner(n2, n2).triangularView<Eigen::Lower>() * b);
}

// The lower triangle of M^T M for lower-triangular M, in place (LAPACK's
// lauum): with M = [P 0; Q R], M^T M = [P^T P + Q^T Q, .; R^T Q, R^T R].
// n^3/3 flops instead of the n^3 of a general symmetric product.
void lower_gram_in_place(Eigen::Ref<Eigen::MatrixXd> m) {
  const Eigen::Index n = m.rows();
  constexpr Eigen::Index kDirect = 64;
  if (n <= kDirect) {
    const Eigen::MatrixXd lower = m.triangularView<Eigen::Lower>();
    m.triangularView<Eigen::Lower>() = lower.transpose() * lower;
    return;
  }
  const Eigen::Index n1 = n / 2;
  const Eigen::Index n2 = n - n1;
  lower_gram_in_place(m.topLeftCorner(n1, n1));
  m.topLeftCorner(n1, n1).selfadjointView<Eigen::Lower>().rankUpdate(m.bottomLeftCorner(n2, n1).transpose());
  m.bottomLeftCorner(n2, n1) =
      m.bottomRightCorner(n2, n2).triangularView<Eigen::Lower>().transpose() * m.bottomLeftCorner(n2, n1);
  lower_gram_in_place(m.bottomRightCorner(n2, n2));
}

struct Factorisation {
  Eigen::LLT<Eigen::MatrixXd> llt;
  double jitter = 0.0;
};

// Adds the noise, then jitter growing by decades from 1e-10 of the signal
// variance until the Cholesky factorisation succeeds.
Factorisation factorise(Eigen::MatrixXd k, double noise_variance, double signal_variance) {
  k.diagonal().array() += noise_variance;
  Factorisation f;
  f.llt.compute(k);
  double jitter = 1e-10 * signal_variance;
  while (f.llt.info() != Eigen::Success) {
    if (jitter > 1e-2 * signal_variance) {
      throw std::runtime_error("kernel matrix is not positive definite even with jitter");
    }
    k.diagonal().array() += jitter - f.jitter;
    f.jitter = jitter;
    f.llt.compute(k);
    jitter *= 10.0;
  }
  return f;
}

}  // namespace

LikelihoodResult log_marginal_likelihood(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y,
                                         const KernelHyperparameters& h, bool with_gradient) {
  const Eigen::Index n = x.rows();
  const Eigen::Index d = x.cols();
  const double outputs = static_cast<double>(y.cols());
  const Eigen::MatrixXd k_signal = gram_matrix(x, h);
  const Factorisation f = factorise(k_signal, h.noise_variance, h.signal_variance);
  const Eigen::MatrixXd alpha = f.llt.solve(y);
  const Eigen::MatrixXd& l = f.llt.matrixLLT();

  LikelihoodResult result;
  result.jitter = f.jitter;
  const double log_det = 2.0 * l.diagonal().array().log().sum();
  result.log_marginal_likelihood = -0.5 * (y.array() * alpha.array()).sum() - 0.5 * outputs * log_det -
                                   0.5 * outputs * static_cast<double>(n) * std::log(2.0 * kPi);
  if (!with_gradient) return result;

  // dLML/dp = 1/2 tr(W dK/dp), W = alpha alpha^T - m K^-1.
  // K^-1 = L^-T L^-1, as LAPACK's potri does it: invert L, then form the
  // lower triangle of the product; together n^3 * 2/3 flops, the dominant
  // cost of an evaluation.
  Eigen::MatrixXd k_inverse = l.triangularView<Eigen::Lower>();
  invert_lower_triangular(k_inverse);
  lower_gram_in_place(k_inverse);
  Eigen::MatrixXd w = -outputs * k_inverse.selfadjointView<Eigen::Lower>().toDenseMatrix();
  w.noalias() += alpha * alpha.transpose();

  result.gradient = Eigen::VectorXd::Zero(d + 2);
  // With a = scaled inputs and M = W .* K_signal (symmetric):
  //   1/2 sum_ij M_ij (a_id - a_jd)^2 = sum_i a_id^2 (M 1)_i - (a^T M a)_dd,
  // two matrix products instead of a loop over pairs.
  const Eigen::MatrixXd a = x.array().rowwise() * h.length_scales.cwiseInverse().transpose().array();
  const Eigen::MatrixXd m = w.cwiseProduct(k_signal);
  const Eigen::VectorXd row_sums = m.rowwise().sum();
  const Eigen::MatrixXd ma = m * a;
  result.gradient.head(d) = (a.array().square().matrix().transpose() * row_sums) -
                            a.cwiseProduct(ma).colwise().sum().transpose();
  result.gradient[d] = 0.5 * (w.array() * k_signal.array()).sum();
  result.gradient[d + 1] = 0.5 * h.noise_variance * w.trace();
  return result;
}

GaussianProcess GaussianProcess::fit(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y,
                                     const KernelHyperparameters& h) {
  const Factorisation f = factorise(gram_matrix(x, h), h.noise_variance, h.signal_variance);
  GaussianProcess gp;
  gp.hyperparameters = h;
  gp.inputs = x;
  gp.alpha = f.llt.solve(y);
  gp.jitter = f.jitter;
  return gp;
}

Eigen::MatrixXd GaussianProcess::predict(const Eigen::MatrixXd& queries) const {
  return kernel_matrix(queries, inputs, hyperparameters) * alpha;
}

}  // namespace cdcr::training
