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
  int model_points = 0;  // N for the exact GP, M for the sparse one
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

// The same on a test set collected apart: every row of `pool` may train. A
// sparse model (options.model) gets min(options.inducing_points, N) points.
LearningCurve learning_curve(const TrainingSet& pool, const TrainingSet& test, const std::vector<int>& sizes,
                             std::uint64_t seed, const TrainingOptions& options,
                             const model::RobotGeometry<double>& geometry);

// A sparse GP on the first `samples` of the shuffled pool with each of
// `inducing_sizes` inducing points: the error against M at a fixed N.
LearningCurve inducing_curve(const TrainingSet& pool, const TrainingSet& test, int samples,
                             const std::vector<int>& inducing_sizes, std::uint64_t seed, TrainingOptions options,
                             const model::RobotGeometry<double>& geometry);

}  // namespace cdcr::training
