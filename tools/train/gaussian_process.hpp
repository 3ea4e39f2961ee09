#pragma once
// Exact Gaussian-process regression in double precision, for training: the
// squared-exponential kernel with ARD length scales, its log marginal
// likelihood and the analytic gradient of that likelihood.
//
// Hyperparameters are optimised in log space, in this order:
//   [log l_1, ..., log l_D, log signal_variance, log noise_variance]
// (the same parametrisation as scikit-learn's ConstantKernel * RBF + WhiteKernel,
// so the two can be compared number for number).
//
// A GP may carry several output columns that share the kernel; its log
// marginal likelihood is then the sum over the columns, as in scikit-learn's
// multi-output regression.

#include <Eigen/Core>

namespace cdcr::training {

struct KernelHyperparameters {
  Eigen::VectorXd length_scales;  // D, in the units of the (normalised) inputs
  double signal_variance = 1.0;
  double noise_variance = 1e-2;

  int input_dims() const { return static_cast<int>(length_scales.size()); }
  Eigen::VectorXd to_log() const;
  static KernelHyperparameters from_log(const Eigen::VectorXd& log_parameters);
};

// K_ij = signal_variance * exp(-1/2 sum_d ((a_id - b_jd) / l_d)^2), no noise term.
Eigen::MatrixXd kernel_matrix(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const KernelHyperparameters& h);

// The kernel matrix of a set with itself: exactly symmetric with the
// diagonal exactly signal_variance, which a Cholesky factorisation relies on.
Eigen::MatrixXd gram_matrix(const Eigen::MatrixXd& x, const KernelHyperparameters& h);

struct LikelihoodResult {
  double log_marginal_likelihood = 0.0;
  Eigen::VectorXd gradient;  // d LML / d log-parameters, see the order above
  double jitter = 0.0;       // diagonal added beyond the noise to make K positive definite
};

// The N x N buffers of an evaluation, kept by a search from one evaluation
// to the next: allocating (and first touching) them anew costs as much as
// the arithmetic on some machines.
struct LikelihoodWorkspace {
  Eigen::MatrixXd scaled_inputs;  // N x D
  Eigen::MatrixXd k_signal;       // N x N, lower triangle
  Eigen::MatrixXd factor;         // N x N: the Cholesky factor, then K^-1 (lower triangles)
  Eigen::MatrixXd alpha;          // N x m
  Eigen::VectorXd column;         // N
};

// X: N x D inputs, Y: N x m outputs (already normalised). Throws
// std::runtime_error if K cannot be factorised even with jitter.
LikelihoodResult log_marginal_likelihood(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y,
                                         const KernelHyperparameters& h, bool with_gradient = true);
LikelihoodResult log_marginal_likelihood(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y,
                                         const KernelHyperparameters& h, bool with_gradient,
                                         LikelihoodWorkspace& workspace);

// A fitted GP: the training inputs, alpha = (K + noise I)^-1 Y, and the kernel.
struct GaussianProcess {
  KernelHyperparameters hyperparameters;
  Eigen::MatrixXd inputs;  // N x D
  Eigen::MatrixXd alpha;   // N x m
  double jitter = 0.0;

  static GaussianProcess fit(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y, const KernelHyperparameters& h);

  // Posterior mean at the rows of `queries`: Q x m.
  Eigen::MatrixXd predict(const Eigen::MatrixXd& queries) const;
};

}  // namespace cdcr::training
