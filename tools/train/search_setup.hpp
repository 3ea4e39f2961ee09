#pragma once
// What the exact and the sparse searches set up alike: the log-space box of
// the kernel's hyperparameters and the L-BFGS-B settings. Included by the
// two searches' sources only (LBFGSpp stays out of the public headers).

#include <cmath>

#include <Eigen/Core>
#include <LBFGSB.h>

#include "hyperparameter_search.hpp"

namespace cdcr::training::detail {

// [log l (length_entries of them), log signal variance, log noise variance]
// into the first length_entries + 2 entries of lower and upper.
inline void set_hyperparameter_box(const SearchBounds& b, Eigen::Index length_entries, Eigen::VectorXd& lower,
                                   Eigen::VectorXd& upper) {
  lower.head(length_entries).setConstant(std::log(b.length_scale_min));
  upper.head(length_entries).setConstant(std::log(b.length_scale_max));
  lower[length_entries] = std::log(b.signal_variance_min);
  upper[length_entries] = std::log(b.signal_variance_max);
  lower[length_entries + 1] = std::log(b.noise_variance_min);
  upper[length_entries + 1] = std::log(b.noise_variance_max);
}

inline LBFGSpp::LBFGSBParam<double> lbfgsb_parameters(const SearchOptions& options) {
  LBFGSpp::LBFGSBParam<double> param;
  param.epsilon = options.gradient_tolerance;
  param.max_iterations = options.max_iterations;
  param.max_linesearch = 40;
  return param;
}

}  // namespace cdcr::training::detail
