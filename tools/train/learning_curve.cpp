#include "learning_curve.hpp"

#include <algorithm>
#include <chrono>
#include <random>
#include <stdexcept>
#include <string>

#include "training_set.hpp"

namespace cdcr::training {

namespace {

// Nested subsets: the first N of one seeded shuffle of the pool.
std::vector<int> shuffled_rows(int rows, std::uint64_t seed) {
  std::vector<int> order(static_cast<std::size_t>(rows));
  for (int i = 0; i < rows; ++i) order[static_cast<std::size_t>(i)] = i;
  std::mt19937_64 rng(seed + 1);
  std::shuffle(order.begin(), order.end(), rng);
  return order;
}

TrainingSet first_rows(const TrainingSet& pool, const std::vector<int>& order, int n) {
  if (n < 2 || n > static_cast<int>(order.size())) {
    throw std::invalid_argument("training size " + std::to_string(n) + " is outside the pool of " +
                                std::to_string(order.size()) + " samples");
  }
  return pool.subset(std::vector<int>(order.begin(), order.begin() + n));
}

LearningCurvePoint measured_point(const TrainingSet& train_set, const TrainingSet& test,
                                  const TrainingOptions& options, const model::RobotGeometry<double>& geometry) {
  const auto start = std::chrono::steady_clock::now();
  const Compensator c = fit_compensator(train_set, geometry, options);
  LearningCurvePoint p;
  p.training_samples = train_set.size();
  p.model_points = static_cast<int>(c.shared.inputs.rows());
  p.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  p.compensated = evaluate(test, c.predict(test)).compensated;
  return p;
}

}  // namespace

LearningCurve learning_curve(const TrainingSet& all, const std::vector<int>& sizes, int test_count,
                             std::uint64_t seed, const TrainingOptions& options,
                             const model::RobotGeometry<double>& geometry) {
  const Split split = random_split(all.size(), test_count, seed);
  return learning_curve(all.subset(split.train), all.subset(split.test), sizes, seed, options, geometry);
}

LearningCurve learning_curve(const TrainingSet& pool, const TrainingSet& test, const std::vector<int>& sizes,
                             std::uint64_t seed, const TrainingOptions& options,
                             const model::RobotGeometry<double>& geometry) {
  const std::vector<int> order = shuffled_rows(pool.size(), seed);
  LearningCurve curve;
  curve.test_samples = test.size();
  curve.initial = mean_errors(test.measured, test.nominal);
  for (const int n : sizes) {
    // A sparse model has at most one inducing point per row.
    TrainingOptions at_size = options;
    if (options.model == ModelChoice::sparse) at_size.inducing_points = std::min(options.inducing_points, n);
    curve.points.push_back(measured_point(first_rows(pool, order, n), test, at_size, geometry));
  }
  return curve;
}

LearningCurve inducing_curve(const TrainingSet& pool, const TrainingSet& test, int samples,
                             const std::vector<int>& inducing_sizes, std::uint64_t seed, TrainingOptions options,
                             const model::RobotGeometry<double>& geometry) {
  const TrainingSet train_set = first_rows(pool, shuffled_rows(pool.size(), seed), samples);
  LearningCurve curve;
  curve.test_samples = test.size();
  curve.initial = mean_errors(test.measured, test.nominal);
  options.model = ModelChoice::sparse;
  for (const int m : inducing_sizes) {
    if (m < 1 || m > samples) {
      throw std::invalid_argument("inducing size " + std::to_string(m) + " is outside 1.." + std::to_string(samples));
    }
    options.inducing_points = m;
    curve.points.push_back(measured_point(train_set, test, options, geometry));
  }
  return curve;
}

}  // namespace cdcr::training
