#pragma once
// Maximum-likelihood hyperparameters: L-BFGS-B (LBFGSpp) on the negative log
// marginal likelihood with its analytic gradient, in log space, inside bounds,
// from a fixed start plus random restarts. The best optimum wins.

#include <cstdint>

#include <Eigen/Core>

#include "gaussian_process.hpp"

namespace cdcr::training {

struct SearchBounds {
  double length_scale_min = 1e-2;
  double length_scale_max = 1e3;
  double signal_variance_min = 1e-3;
  double signal_variance_max = 1e3;
  double noise_variance_min = 1e-6;  // keeps K well conditioned; normalised output units
  double noise_variance_max = 1e1;
};

struct SearchOptions {
  int restarts = 2;  // in addition to the start from `initial`
  std::uint64_t seed = 1;
  int max_iterations = 200;
  // The paper's kernel: one length scale for every input (sigma^2, l^2)
  // instead of one per input (ARD).
  bool isotropic = false;
  double gradient_tolerance = 1e-5;  // relative, LBFGSpp's epsilon
  SearchBounds bounds;
};

struct SearchResult {
  KernelHyperparameters hyperparameters;
  double log_marginal_likelihood = 0.0;
  int likelihood_evaluations = 0;
  int optimisations_completed = 0;  // starts that ended without a numerical failure
};

// X: N x D normalised inputs, Y: N x m normalised outputs sharing one kernel.
SearchResult maximise_likelihood(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y,
                                 const KernelHyperparameters& initial, const SearchOptions& options = {});

// A sensible start for normalised data: unit length scales and signal
// variance, noise a tenth of the signal.
KernelHyperparameters default_initial_hyperparameters(int input_dims);

}  // namespace cdcr::training
