#pragma once
// The paper's protocol (Section V-B): hold out a test set, then train on
// growing subsets of the remaining pool and report the mean residual error
// on the same test set each time (Table 3, Figs. 7-8).

#include <cstdint>
#include <vector>

#include "evaluation.hpp"
#include "trainer.hpp"
#include "training_set.hpp"

namespace cdcr::training {

struct LearningCurvePoint {
  int training_samples = 0;
  MeanErrors compensated;
  double seconds = 0.0;
};

struct LearningCurve {
  int test_samples = 0;
  MeanErrors initial;  // nominal model on the test set
  std::vector<LearningCurvePoint> points;
};

// Subsets are nested: the first N of one seeded shuffle of the pool, so a
// larger N only ever adds samples.
LearningCurve learning_curve(const TrainingSet& all, const std::vector<int>& sizes, int test_count,
                             std::uint64_t seed, const TrainingOptions& options,
                             const model::RobotGeometry<double>& geometry);

}  // namespace cdcr::training
