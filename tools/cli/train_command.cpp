#include "training_commands.hpp"

#include <chrono>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_errors.hpp"
#include "dataset_input.hpp"
#include "export/binary_file.hpp"
#include "train/calibration.hpp"
#include "pipeline/train_and_export.hpp"
#include "train_report.hpp"
#include "training_options.hpp"

namespace cdcr::cli {
namespace {

struct TrainCommandOptions {
  std::string data_path;
  std::string validation_path;
  std::string out_path;
  int holdout = 50;
  std::string model = "auto";
  int inducing = 0;
  int variance_points = 64;
  std::uint64_t flash_budget = 96 * 1024;
  GeometryOptions geometry;
  TrainingFlags training;
  bool calibrate = false;
  bool ignore_payload = false;
  bool no_hysteresis = false;
  bool no_history = false;
  bool no_homing = false;
  bool no_compliance = false;
  bool json = false;
};

// The command line's choices as the trainer takes them.
training::TrainingOptions training_options_for(const TrainCommandOptions& o) {
  training::TrainingOptions options = make_training_options(o.training);
  options.model = o.model == "exact"    ? training::ModelChoice::exact
                  : o.model == "sparse" ? training::ModelChoice::sparse
                                        : training::ModelChoice::automatic;
  if (o.inducing < 0) throw InputError(fmt::format("--inducing must not be negative (got {})", o.inducing));
  if (o.inducing > 0 && options.model == training::ModelChoice::exact) {
    throw InputError("--inducing applies to a sparse model, not to --model exact");
  }
  options.inducing_points = o.inducing;
  if (o.variance_points < 0 || o.variance_points > static_cast<int>(model::kMaxVarianceRank)) {
    throw InputError(fmt::format("--variance-points must be between 0 and {} (got {})", model::kMaxVarianceRank,
                                 o.variance_points));
  }
  options.variance_rank = o.variance_points;
  if (o.flash_budget > std::numeric_limits<std::uint32_t>::max()) {
    throw InputError(fmt::format("--flash-budget {} is beyond a 32-bit image size", o.flash_budget));
  }
  options.board.flash_budget_bytes = static_cast<std::uint32_t>(o.flash_budget);
  options.offer_history = !o.no_history;
  return options;
}

// The rows, split for validation, with a given geometry (the split depends
// only on the row count, so the design's and the calibrated geometry's sets
// hold the same rows).
struct TrainingSets {
  training::TrainingSet all, train, validation;
  // The rows of --data in train and validation (none in validation when
  // --validation gives them), and the --validation data.
  std::vector<int> train_rows, validation_rows;
  std::optional<dataset::Dataset> validation_data;
};

std::vector<int> every_row(int count) {
  std::vector<int> rows(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) rows[static_cast<std::size_t>(i)] = i;
  return rows;
}

TrainingSets training_sets_for(const TrainCommandOptions& o, const dataset::Dataset& data,
                               const model::RobotGeometry<double>& g, model::InputEncoding encoding) {
  TrainingSets sets;
  try {
    const bool with_payload = !o.ignore_payload;
    sets.all = training::make_training_set(data, g, encoding, with_payload);
    if (!o.validation_path.empty()) {
      sets.train = sets.all;
      sets.train_rows = every_row(sets.all.size());
      sets.validation_data = load_dataset(o.validation_path, true);
      sets.validation_data->sessions_homed = !o.no_homing;
      sets.validation = training::make_training_set(*sets.validation_data, g, encoding, with_payload);
      if (sets.validation.has_payload() != sets.all.has_payload()) {
        throw InputError(fmt::format("{} {} a payload_kg column and {} {}", o.data_path,
                                     sets.all.has_payload() ? "has" : "has no", o.validation_path,
                                     sets.validation.has_payload() ? "has" : "has none"));
      }
    } else if (o.holdout == 0) {
      sets.train = sets.all;
      sets.train_rows = every_row(sets.all.size());
    } else {
      if (o.holdout < 0) throw InputError(fmt::format("--holdout must not be negative (got {})", o.holdout));
      if (sets.all.size() - o.holdout < 2) {
        throw InputError(fmt::format("--holdout {} leaves {} of the {} samples to train on; training needs at least 2",
                                     o.holdout, std::max(0, sets.all.size() - o.holdout), sets.all.size()));
      }
      const training::Split split = training::random_split(sets.all.size(), o.holdout, o.training.seed);
      sets.train = sets.all.subset(split.train);
      sets.validation = sets.all.subset(split.test);
      sets.train_rows = split.train;
      sets.validation_rows = split.test;
    }
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: {}", o.data_path, e.what()));
  }
  return sets;
}

// --encoding auto: the residuals of the cable fit join the bend where the
// evidence on the training rows keeps them. An encoding given by name must
// read every row on the board.
std::optional<training::CableInputChoice> choose_encoding(const TrainCommandOptions& o, TrainingSets& sets,
                                                          const dataset::Dataset& data,
                                                          const model::RobotGeometry<double>& geometry,
                                                          training::TrainingOptions& options) {
  const int beyond_limit =
      sets.all.beyond_limit_rows + (sets.validation_data ? sets.validation.beyond_limit_rows : 0);
  if (o.training.encoding != "auto") {
    if (!model::takes_cable_residuals(options.encoding) && beyond_limit > 0) {
      throw InputError(fmt::format(
          "{}: {} rows bend beyond the limit or the anchors' reach, which --encoding {} cannot read on the board; "
          "use --encoding auto or bend-vector+cable-fit, or raise --theta-max",
          o.data_path, beyond_limit, o.training.encoding));
    }
    return std::nullopt;
  }
  if (sets.train.size() < 2) return std::nullopt;  // reported with the other counts below
  training::CableInputChoice choice;
  try {
    choice = training::choose_cable_inputs(sets.train, options, beyond_limit > 0);
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: {}", o.data_path, e.what()));
  }
  if (choice.encoding != options.encoding) {
    options.encoding = choice.encoding;
    sets = training_sets_for(o, data, geometry, options.encoding);
  }
  return choice;
}

CommandOutput run_train(const TrainCommandOptions& o) {
  training::TrainingOptions options = training_options_for(o);
  dataset::Dataset data = load_dataset(o.data_path, true);
  if (o.no_homing && !data.has_time) {
    throw InputError(fmt::format(
        "{}: --no-homing applies to a motion sequence (a t_s column), but the rows have no time", o.data_path));
  }
  data.sessions_homed = !o.no_homing;
  const model::RobotGeometry<double> design = geometry_for(data, o.geometry);

  TrainingSets sets = training_sets_for(o, data, design, options.encoding);
  std::optional<training::Calibration> calibration;
  model::RobotGeometry<double> geometry = design;
  // Rows too few to identify the geometry, or a search that leaves the
  // plausible range, keep the design geometry; the output says why.
  std::string calibration_skipped;
  if (o.calibrate && sets.train.size() >= 2) {
    try {
      calibration = training::calibrate_geometry(sets.train, design);
      geometry = calibration->geometry;
      sets = training_sets_for(o, data, geometry, options.encoding);
    } catch (const std::invalid_argument& e) {
      calibration.reset();
      calibration_skipped = e.what();
    }
  }
  const std::optional<training::CableInputChoice> cable_inputs = choose_encoding(o, sets, data, geometry, options);
  const training::TrainingSet& all = sets.all;
  const training::TrainingSet& train_set = sets.train;
  const training::TrainingSet& validation_set = sets.validation;
  if (train_set.size() < 2) {
    throw InputError(fmt::format("{}: {} sample{}; training needs at least 2", o.data_path, train_set.size(),
                                 train_set.size() == 1 ? "" : "s"));
  }
  // The exported model is fitted on every row of --data once the held-out
  // rows have measured it; a model too large for the board is sparse (a
  // request the board cannot hold is refused before any training).
  const training::TrainingSet& fitted_set = all;

  const auto now = std::chrono::system_clock::now();
  const auto start = std::chrono::steady_clock::now();
  const std::int64_t created_unix_s = std::chrono::duration_cast<std::chrono::seconds>(now.time_since_epoch()).count();
  // A motion sequence: the hysteresis is identified on the training rows
  // (or the reason it is not is reported) before the GP is fitted.
  std::optional<training::SequenceExport> sequence;
  if (data.has_time && !o.no_hysteresis) {
    try {
      sequence = training::train_and_export_sequence(
          data, sets.train_rows, sets.validation_rows, sets.validation_data ? &*sets.validation_data : nullptr,
          geometry, options, !o.ignore_payload, data.content_hash, created_unix_s);
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("{}: {}", o.data_path, e.what()));
    }
  }
  // Payload data: the segments' compliance under the load is identified on
  // the training rows (or the reason it is not is reported) before the GP.
  std::optional<training::PayloadExport> payload;
  if (!sequence && all.has_payload() && !o.no_compliance) {
    payload = training::train_and_export_payload(train_set, validation_set, fitted_set, geometry, options,
                                                 data.content_hash, created_unix_s);
  }
  const training::ExportResult r =
      sequence  ? sequence->result
      : payload ? payload->result
                : training::train_and_export(train_set, validation_set, fitted_set, geometry, options,
                                             data.content_hash, created_unix_s);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  try {
    exporting::write_binary_file(o.out_path, r.image.data(), r.image.size());
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }

  TrainRun run;
  run.result = &r;
  run.train_rows = train_set.size();
  run.validation_rows = validation_set.size();
  run.validation_path = o.validation_path;
  run.out_path = o.out_path;
  run.kernel = o.training.kernel;
  run.board = options.board;
  run.data_has_payload = data.has_payload;
  run.geometry = geometry;
  run.calibration = calibration;
  run.calibration_skipped = calibration_skipped;
  run.sequence = sequence ? &*sequence : nullptr;
  run.data_has_time = data.has_time;
  run.payload = payload ? &*payload : nullptr;
  run.payload_input = all.has_payload();
  run.cable_inputs = cable_inputs ? &*cable_inputs : nullptr;
  run.data_rows = all.size();
  run.far_from_consistent_rows = all.far_from_consistent_rows;
  run.beyond_limit_rows = all.beyond_limit_rows;
  run.seconds = seconds;
  CommandOutput output;
  output.text = o.json ? train_report_json(run) : train_report_text(run);
  return output;
}

}  // namespace

void register_train_command(CLI::App& app, CommandOutput& output) {
  auto o = std::make_shared<TrainCommandOptions>();
  CLI::App* command = app.add_subcommand("train", "Train the GP compensation model and export a flash image");
  command->add_option("--data", o->data_path, "Training dataset CSV (cables and measured poses)")->required();
  command->add_option("--out", o->out_path, "Flash image to write")->required();
  command->add_option("--validation", o->validation_path,
                      "Held-out dataset CSV for the accuracy and float32 figures (default: hold out --holdout "
                      "samples of --data)");
  command->add_option("--holdout", o->holdout,
                      "Samples of --data held out to validate when --validation is not given (0: none); the exported "
                      "model is then fitted on every row")
      ->capture_default_str();
  command->add_option("--model", o->model,
                      "exact: one point per row; sparse: M inducing points; auto: exact while its points fit the "
                      "board (capacity, --flash-budget, the Cortex-M7 forward cycle), else sparse")
      ->check(CLI::IsMember({"auto", "exact", "sparse"}))
      ->capture_default_str();
  command->add_option("--inducing", o->inducing, "Inducing points M of a sparse model (0: the most that fit the board)")
      ->capture_default_str();
  command->add_option("--variance-points", o->variance_points,
                      "Points R of the predictive-variance factor the image carries (0: no variance; the board "
                      "spends R kernel values and R (R + 1) multiply-adds on it per cycle)")
      ->capture_default_str();
  command->add_option("--flash-budget", o->flash_budget, "Largest image, in bytes (suffixes K, KiB, M accepted)")
      ->transform(CLI::AsSizeValue(false))
      ->default_str("96KiB");
  command->add_flag("--calibrate", o->calibrate,
                    "Identify each segment's backbone length and anchor radius (its bending gain) from the data "
                    "before the GP, and ship the calibrated geometry in the image");
  add_geometry_options(*command, o->geometry, "Number of segments (default: from the dataset's cable columns)");
  add_training_flags(*command, o->training);
  command->add_flag("--ignore-payload", o->ignore_payload,
                    "Train on the cables alone even when the data have a payload_kg column");
  command->add_flag("--no-hysteresis", o->no_hysteresis,
                    "Train the joints-only model even when the data are a motion sequence (a t_s column)");
  command->add_flag("--no-history", o->no_history,
                    "Keep where each cable last moved out of a motion sequence's model (by default it becomes an "
                    "input where the evidence supports it)");
  command->add_flag("--no-homing", o->no_homing,
                    "The sequence's sessions start at power-up without the homing move: their first rows train with "
                    "the cables' state unknown, as the board's are after power-up");
  command->add_flag("--no-compliance", o->no_compliance,
                    "Train the payload-as-an-input model without identifying the segments' compliance under the "
                    "load, even when the data have a payload_kg column");
  command->add_flag("--json", o->json, "Print one JSON object");
  command->callback([o, &output] { output = run_train(*o); });
}

}  // namespace cdcr::cli
