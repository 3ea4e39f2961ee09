#pragma once
// Sparse GP regression by Titsias' variational free energy (VFE): M
// inducing inputs Z stand for the N training inputs. The collapsed bound
//
//   F = log N(y | 0, Q + s2 I) - tr(K_ff - Q) / (2 s2),   Q = K_fu K_uu^-1 K_uf,
//
// is a lower bound on the exact log marginal likelihood, reached when Z are
// the training inputs themselves. Z and the kernel's hyperparameters are
// found together by maximising F, whose gradient here is analytic; one
// evaluation costs O(N M^2). The posterior mean is
//
//   m(x) = k(x, Z) beta,   beta = (s2 K_uu + K_uf K_fu)^-1 K_uf y,
//
// the same sum over M points as the exact GP's over N, so a board evaluates
// it with the same loop, an M-point image in place of an N-point one.
//
// Outputs share the kernel and Z, as in the exact GP (gaussian_process.hpp):
// the bound is the sum of the columns' bounds.

#include <cstdint>

#include <Eigen/Core>

#include "gaussian_process.hpp"
#include "hyperparameter_search.hpp"

namespace cdcr::training {

// The optimised parameters, in this order: the exact GP's
// [log l_1..l_D, log signal_variance, log noise_variance], then Z row by
// row (M x D, in the units of the normalised inputs).
struct SparseParameters {
  KernelHyperparameters hyperparameters;
  Eigen::MatrixXd inducing;  // M x D

  Eigen::VectorXd to_vector() const;
  static SparseParameters from_vector(const Eigen::VectorXd& vector, int input_dims);
};

struct SparseBound {
  double value = 0.0;
  Eigen::VectorXd gradient;  // d F / d (the parameters in SparseParameters order)
  double jitter = 0.0;       // added to K_uu's diagonal beyond 1e-8 of the signal variance
};

// x: N x D inputs, y: N x m outputs (normalised). Throws std::runtime_error
// if K_uu cannot be factorised even with jitter.
SparseBound sparse_bound(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y, const SparseParameters& p,
                         bool with_gradient = true);

struct SparseGaussianProcess {
  SparseParameters parameters;
  Eigen::MatrixXd beta;  // M x m

  static SparseGaussianProcess fit(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y, const SparseParameters& p);
  // Posterior mean at the rows of `queries`: Q x m.
  Eigen::MatrixXd predict(const Eigen::MatrixXd& queries) const;
};

// M rows of x to start the inducing inputs from: k-means++ seeding (each
// next row drawn with probability proportional to its squared distance from
// the rows already chosen), so that they spread over where the data are.
Eigen::MatrixXd initial_inducing_inputs(const Eigen::MatrixXd& x, int m, std::uint64_t seed);

struct SparseSearchResult {
  SparseParameters parameters;
  double bound = 0.0;
  int bound_evaluations = 0;
};

// Maximises the bound over the hyperparameters (within options.bounds) and
// the inducing inputs together with L-BFGS-B, from `initial` (one start:
// the inducing inputs make the problem large, and they are started where
// the data are). options.restarts and options.isotropic are not used.
SparseSearchResult maximise_sparse_bound(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y,
                                         const SparseParameters& initial, const SearchOptions& options = {});

}  // namespace cdcr::training
