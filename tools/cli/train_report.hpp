#pragma once
// cdcr train's report of a finished run: one JSON object, or the text a
// person reads. Nothing here trains or writes a file.

#include <optional>
#include <string>

#include "pipeline/train_and_export.hpp"
#include "train/cable_inputs.hpp"
#include "train/calibration.hpp"
#include "train/model_selection.hpp"

namespace cdcr::cli {

// What a run of cdcr train did, for its report.
struct TrainRun {
  const training::ExportResult* result = nullptr;
  int train_rows = 0;
  int validation_rows = 0;
  // Empty when the validation rows were held out of --data.
  std::string validation_path;
  std::string out_path;
  std::string kernel;
  training::BoardLimits board;
  bool data_has_payload = false;
  model::RobotGeometry<double> geometry;
  std::optional<training::Calibration> calibration;
  std::string calibration_skipped;  // why the design geometry was kept, when --calibrate was asked
  // A motion sequence's hysteresis identification (null: the data have no
  // t_s column, or --no-hysteresis).
  const training::SequenceExport* sequence = nullptr;
  bool data_has_time = false;
  // Payload data's compliance identification (null: no payload input, a
  // motion sequence, or --no-compliance).
  const training::PayloadExport* payload = nullptr;
  bool payload_input = false;  // the model takes the payload
  // The choice of the cables' residuals as inputs (null: an encoding given
  // by --encoding), and the rows the cable fit found far from consistent or
  // beyond the bend limit, of `data_rows`.
  const training::CableInputChoice* cable_inputs = nullptr;
  int data_rows = 0;
  int far_from_consistent_rows = 0;
  int beyond_limit_rows = 0;
  double seconds = 0;
};

std::string train_report_json(const TrainRun& run);
std::string train_report_text(const TrainRun& run);

}  // namespace cdcr::cli
