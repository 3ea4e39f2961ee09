#pragma once
// The training PC's job end to end: split, train, evaluate on held-out data,
// export the image, and measure the float32 firmware path against the
// double-precision trainer on the same held-out samples.

#include <cstdint>
#include <utility>
#include <vector>

#include "evaluation.hpp"
#include "trainer.hpp"
#include "training_set.hpp"

namespace cdcr::training {

struct Split {
  std::vector<int> train;
  std::vector<int> test;
};

// test_count samples drawn at random (seeded), the rest in order for training.
Split random_split(int samples, int test_count, std::uint64_t seed);

// The targets of the float32 export (issue: firmware fidelity).
inline constexpr double kFidelityTargetPositionMm = 0.01;
inline constexpr double kFidelityTargetOrientationDeg = 0.001;

struct ExportResult {
  TrainedModel model;
  TrainingReport report;
  std::vector<std::uint8_t> image;
  Evaluation validation;  // double-precision trainer on the held-out samples
  Evaluation firmware;    // float32 image path (double accumulators) on the same samples
  // float32 path vs double trainer, one entry per FirmwareAccumulator.
  std::vector<std::pair<FirmwareAccumulator, Fidelity>> fidelity_by_accumulator;
  Fidelity fidelity;      // the worst of the accumulators that firmware builds use

  static bool meets_target(const Fidelity& f) {
    return f.max_position_mm <= kFidelityTargetPositionMm && f.max_orientation_deg <= kFidelityTargetOrientationDeg;
  }
  bool fidelity_met() const { return meets_target(fidelity); }
};

ExportResult train_and_export(const TrainingSet& train_set, const TrainingSet& validation_set,
                              const model::RobotGeometry<double>& geometry, const TrainingOptions& options,
                              std::uint64_t dataset_hash, std::int64_t created_unix_s);

}  // namespace cdcr::training
