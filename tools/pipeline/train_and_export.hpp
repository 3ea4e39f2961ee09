#pragma once
// The training PC's job end to end: train, evaluate on held-out data, fit
// the exported model on every row, export the image, and measure the float32
// firmware path against the double-precision trainer. It sits above both the
// trainer (train/) and the image writer (export/), which know nothing of
// each other: the model they share is trained_model/.

#include <cstdint>
#include <utility>
#include <vector>

#include "cdcr/model/hysteresis.hpp"
#include "dataset/dataset.hpp"
#include "train/compliance_identification.hpp"
#include "train/evaluation.hpp"
#include "train/history_inputs.hpp"
#include "train/hysteresis_identification.hpp"
#include "train/predictive_variance.hpp"
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
  // The radii's calibration of the exported model (rows 0 without a
  // variance factor).
  RadiusCalibration radius_calibration;
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
// have the same rows). A non-empty `hysteresis` is the model's (the sets'
// cables_mm are then the effective lengths it gives; the float32 image path
// is measured on the same effective lengths as the trainer, so the image's
// own hysteresis arithmetic is not part of this check). A non-empty
// `compliance` is the model's too: the sets' nominal poses and error twists
// are then the sagged ones (with_compliance), and the float32 image path,
// which sags the nominal pose itself, is measured against them.
ExportResult train_and_export(const TrainingSet& train_set, const TrainingSet& validation_set,
                              const TrainingSet& fitted_set, const model::RobotGeometry<double>& geometry,
                              const TrainingOptions& options, std::uint64_t dataset_hash,
                              std::int64_t created_unix_s, const model::HysteresisModel<double>& hysteresis = {},
                              const model::PayloadCompliance<double>& compliance = {});

// cdcr train on payload data: the segments' compliance under the tip load
// chosen on the training rows (choose_compliance), then, when a sag model
// wins, the GP trained, measured and exported on the sagged residuals with
// the image's compliance block; otherwise the payload-as-an-input model, as
// train_and_export on the rows as they are.
struct PayloadExport {
  ExportResult result;
  ComplianceChoice choice;
  // The nominal model without the sag on the validation rows (samples 0
  // when none are held out); result.validation.initial is the sagged one.
  Evaluation unsagged_validation;

  bool uses_compliance() const { return !result.model.compliance.empty(); }
};

// The sets must have a payload column (else std::invalid_argument).
PayloadExport train_and_export_payload(const TrainingSet& train_set, const TrainingSet& validation_set,
                                       const TrainingSet& fitted_set, const model::RobotGeometry<double>& geometry,
                                       const TrainingOptions& options, std::uint64_t dataset_hash,
                                       std::int64_t created_unix_s);

// cdcr train on a motion sequence: the hysteresis identified on the training
// rows (see hysteresis_identification.hpp), then the model trained, measured
// and exported on the effective lengths; or the joints-only model, as
// train_and_export on the commanded rows, when the identification is
// skipped (too few rows) or chooses none.
// Retrainings with a raised noise floor, at most, when the float32 image
// of a sequence's model misses the fidelity target.
inline constexpr int kNoiseFloorAttempts = 4;

struct SequenceExport {
  ExportResult result;
  HysteresisIdentification identification;
  // Whether the GP takes where each cable last moved (searched when the
  // identification ran and the options allow it).
  HistoryChoice history;
  // The joints-only model of the same training rows on the validation rows
  // (samples 0 when there are none); its `initial` is the nominal model on
  // the commanded lengths.
  Evaluation joints_only_validation;
  // The noise variance's lower bound (normalised units) the search was given
  // to keep the float32 image within the fidelity target; 0: not raised.
  double noise_variance_floor = 0.0;

  bool uses_hysteresis() const { return !result.model.hysteresis.empty(); }
};

// `data` must be a sequence (has_time). train_rows and validation_rows are
// rows of `data`; with validation_data the validation rows are all of it
// instead (a sequence too, else std::invalid_argument), its state run from
// its own homing. The exported model is fitted on every row of `data`.
SequenceExport train_and_export_sequence(const dataset::Dataset& data, const std::vector<int>& train_rows,
                                         const std::vector<int>& validation_rows,
                                         const dataset::Dataset* validation_data,
                                         const model::RobotGeometry<double>& geometry, const TrainingOptions& options,
                                         bool with_payload, std::uint64_t dataset_hash, std::int64_t created_unix_s,
                                         const HysteresisSearchOptions& search = {});

}  // namespace cdcr::training
