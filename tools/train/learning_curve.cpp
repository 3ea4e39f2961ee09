#include "learning_curve.hpp"

#include <algorithm>
#include <chrono>
#include <random>
#include <stdexcept>
#include <string>

#include "pipeline.hpp"

namespace cdcr::training {

LearningCurve learning_curve(const TrainingSet& all, const std::vector<int>& sizes, int test_count,
                             std::uint64_t seed, const TrainingOptions& options,
                             const model::RobotGeometry<double>& geometry) {
  const Split split = random_split(all.size(), test_count, seed);
  const TrainingSet test = all.subset(split.test);
  std::vector<int> pool = split.train;
  std::mt19937_64 rng(seed + 1);
  std::shuffle(pool.begin(), pool.end(), rng);

  LearningCurve curve;
  curve.test_samples = test.size();
  curve.initial = mean_errors(test.measured, test.nominal);
  for (const int n : sizes) {
    if (n < 2 || n > static_cast<int>(pool.size())) {
      throw std::invalid_argument("training size " + std::to_string(n) + " is outside the pool of " +
                                  std::to_string(pool.size()) + " samples");
    }
    const TrainingSet train_set = all.subset(std::vector<int>(pool.begin(), pool.begin() + n));
    const auto start = std::chrono::steady_clock::now();
    const Compensator c = fit_compensator(train_set, geometry, options);
    LearningCurvePoint p;
    p.training_samples = n;
    p.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    p.compensated = evaluate(test, c.predict(test.bends)).compensated;
    curve.points.push_back(p);
  }
  return curve;
}

}  // namespace cdcr::training
