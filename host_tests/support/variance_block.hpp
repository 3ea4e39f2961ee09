#pragma once
// A test model with a predictive-variance block: one kernel for all six
// outputs (the only form the block holds: the first output's signal and
// noise variances for every output) and a factor of `rank` k-means points
// over the model's own rows; rank 0 keeps the shared kernel only.

#include "train/predictive_variance.hpp"
#include "trained_model/trained_model.hpp"

namespace cdcr::test_support {

inline void add_variance_block(training::TrainedModel& m, int rank, unsigned seed = 1) {
  m.signal_variance.setConstant(m.signal_variance[0]);
  m.noise_variance.setConstant(m.noise_variance[0]);
  if (rank > 0) m.variance = training::fit_variance_factor(m, m.inputs, training::variance_points(m, m.inputs, rank, seed));
}

}  // namespace cdcr::test_support
