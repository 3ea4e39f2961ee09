#pragma once
// The training PC's job end to end: train, evaluate on held-out data, fit
// the exported model on every row, export the image, and measure the float32
// firmware path against the double-precision trainer. It sits above both the
// trainer (train/) and the image writer (export/), which know nothing of
// each other: the model they share is trained_model/.

#include <cstdint>
#include <utility>
#include <vector>

#include "train/evaluation.hpp"
#include "train/trainer.hpp"
#include "train/training_set.hpp"

namespace cdcr::training {

// The float32 image path against the double-precision trainer: the most it may differ.
inline constexpr double kFidelityTargetPositionMm = 0.01;
inline constexpr double kFidelityTargetOrientationDeg = 0.001;

struct ExportResult {
  TrainedModel model;     // the exported one, fitted on `fitted_rows`
  TrainingReport report;
  std::vector<std::uint8_t> image;
  int fitted_rows = 0;
  // The model fitted on the training rows alone, on the held-out samples
  // (none when validation.samples is 0): the double-precision trainer, and
  // the float32 image path with double accumulators.
  Evaluation validation;
  Evaluation firmware;
  // The radii of the model fitted on the training rows, on the held-out
  // samples (samples 0 when none are held out or the image has no variance).
  CoverageCheck validation_coverage;
  // The exported image's float32 path against its double-precision model,
  // on the held-out samples (on the fitted rows when none are held out).
  // float32 path vs double trainer, one entry per FirmwareAccumulator.
  std::vector<std::pair<FirmwareAccumulator, Fidelity>> fidelity_by_accumulator;
  Fidelity fidelity;      // the worst of the accumulators that firmware builds use

  static bool meets_target(const Fidelity& f) {
    return f.max_position_mm <= kFidelityTargetPositionMm && f.max_orientation_deg <= kFidelityTargetOrientationDeg;
  }
  bool fidelity_met() const { return meets_target(fidelity); }
};

// Searches the hyperparameters on train_set, measures that model on
// validation_set (which may be empty), then fits the exported model on
// fitted_set with the same hyperparameters (train_set itself when the two
// have the same rows).
ExportResult train_and_export(const TrainingSet& train_set, const TrainingSet& validation_set,
                              const TrainingSet& fitted_set, const model::RobotGeometry<double>& geometry,
                              const TrainingOptions& options, std::uint64_t dataset_hash,
                              std::int64_t created_unix_s);

}  // namespace cdcr::training
