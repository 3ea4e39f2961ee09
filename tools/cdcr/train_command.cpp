#include "train_command.hpp"

#include <chrono>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_errors.hpp"
#include "dataset_input.hpp"
#include "export/binary_file.hpp"
#include "json_output.hpp"
#include "train/calibration.hpp"
#include "pipeline/train_and_export.hpp"
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
  bool json = false;
};

std::string check_mark(bool ok) { return ok ? "meets target" : "MISSES target"; }

Json errors_json(const training::MeanErrors& e) {
  Json j;
  j["position_mm"] = e.position_mm;
  j["orientation_deg"] = e.orientation_deg;
  return j;
}

CommandOutput run_train(const TrainCommandOptions& o) {
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
  const dataset::Dataset data = load_dataset(o.data_path, true);
  const model::RobotGeometry<double> design = geometry_for(data, o.geometry);

  // The rows, split for validation, with a given geometry: the design's,
  // then the calibrated one's (the split depends only on the row count).
  struct Sets {
    training::TrainingSet all, train, validation;
  };
  const auto build_sets = [&](const model::RobotGeometry<double>& g) {
    Sets sets;
    try {
      const bool with_payload = !o.ignore_payload;
      sets.all = training::make_training_set(data, g, options.encoding, with_payload);
      if (!o.validation_path.empty()) {
        sets.train = sets.all;
        sets.validation =
            training::make_training_set(load_dataset(o.validation_path, true), g, options.encoding, with_payload);
        if (sets.validation.has_payload() != sets.all.has_payload()) {
          throw InputError(fmt::format("{} {} a payload_kg column and {} {}", o.data_path,
                                       sets.all.has_payload() ? "has" : "has no", o.validation_path,
                                       sets.validation.has_payload() ? "has" : "has none"));
        }
      } else if (o.holdout == 0) {
        sets.train = sets.all;
      } else {
        if (o.holdout < 0) throw InputError(fmt::format("--holdout must not be negative (got {})", o.holdout));
        if (sets.all.size() - o.holdout < 2) {
          throw InputError(fmt::format("--holdout {} leaves {} of the {} samples to train on; training needs at least 2",
                                       o.holdout, std::max(0, sets.all.size() - o.holdout), sets.all.size()));
        }
        const training::Split split = training::random_split(sets.all.size(), o.holdout, o.training.seed);
        sets.train = sets.all.subset(split.train);
        sets.validation = sets.all.subset(split.test);
      }
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("{}: {}", o.data_path, e.what()));
    }
    return sets;
  };
  Sets sets = build_sets(design);
  std::optional<training::Calibration> calibration;
  model::RobotGeometry<double> geometry = design;
  // Rows too few to identify the geometry, or a search that leaves the
  // plausible range, keep the design geometry; the output says why.
  std::string calibration_skipped;
  if (o.calibrate && sets.train.size() >= 2) {
    try {
      calibration = training::calibrate_geometry(sets.train, design);
      geometry = calibration->geometry;
      sets = build_sets(geometry);
    } catch (const std::invalid_argument& e) {
      calibration.reset();
      calibration_skipped = e.what();
    }
  }
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
  const training::ExportResult r = training::train_and_export(
      train_set, validation_set, fitted_set, geometry, options, data.content_hash,
      std::chrono::duration_cast<std::chrono::seconds>(now.time_since_epoch()).count());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  try {
    exporting::write_binary_file(o.out_path, r.image.data(), r.image.size());
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }

  CommandOutput output;
  const training::TrainedModel& m = r.model;
  if (o.json) {
    Json j;
    j["training_samples"] = train_set.size();
    j["validation_samples"] = validation_set.size();
    j["fitted_rows"] = r.fitted_rows;
    const training::ModelSelection& selection = r.report.selection;
    j["model"] = {{"kind", training::to_string(selection.kind)},
                  {"points", selection.points},
                  {"largest_points", selection.largest_points},
                  {"image_bytes", selection.image_bytes},
                  {"forward_cycle_instructions_m7", selection.forward_cycle_instructions},
                  {"reason", selection.reason}};
    j["search_rows"] = r.report.search_rows;
    if (calibration) {
      Json segments = Json::array();
      for (int i = 0; i < geometry.segment_count; ++i) {
        segments.push_back({{"backbone_length_mm", geometry.segments[i].backbone_length_mm},
                            {"anchor_radius_mm", geometry.segments[i].anchor_radius_mm}});
      }
      j["calibration"] = {{"segments", segments},
                          {"nominal_before", errors_json(calibration->before)},
                          {"nominal_after", errors_json(calibration->after)},
                          {"evaluations", calibration->evaluations}};
    } else {
      j["calibration"] = nullptr;
    }
    j["calibration_skipped"] = calibration_skipped.empty() ? Json(nullptr) : Json(calibration_skipped);
    j["encoding"] = model::to_string(m.encoding);
    j["payload_input"] = m.has_payload_input();
    j["default_payload_kg"] = m.has_payload_input() ? Json(m.default_payload_kg) : Json(nullptr);
    j["kernel"] = o.training.kernel;
    j["length_scales"] = std::vector<double>(m.length_scales.data(), m.length_scales.data() + m.length_scales.size());
    j["signal_variance"] = m.signal_variance[0];
    j["noise_variance"] = m.noise_variance[0];
    j["log_marginal_likelihood"] = r.report.log_marginal_likelihood;
    j["likelihood_evaluations"] = r.report.likelihood_evaluations;
    j["seconds"] = seconds;
    if (r.validation.samples > 0) {
      j["validation"] = {{"initial", errors_json(r.validation.initial)},
                         {"compensated", errors_json(r.validation.compensated)},
                         {"compensated_float32_image", errors_json(r.firmware.compensated)}};
    } else {
      j["validation"] = nullptr;
    }
    Json fidelity = Json::object();
    for (const auto& [accumulator, f] : r.fidelity_by_accumulator) {
      fidelity[training::to_string(accumulator)] = {{"max_position_mm", f.max_position_mm},
                                                    {"mean_position_mm", f.mean_position_mm},
                                                    {"max_orientation_deg", f.max_orientation_deg},
                                                    {"mean_orientation_deg", f.mean_orientation_deg},
                                                    {"target_met", training::ExportResult::meets_target(f)}};
    }
    j["float32_fidelity"] = fidelity;
    j["float32_fidelity_target_met"] = r.fidelity_met();
    j["image"] = {{"path", o.out_path}, {"bytes", r.image.size()}};
    output.text = j.dump() + "\n";
  } else {
    std::string t;
    if (validation_set.size() > 0) {
      t += fmt::format("trained on {} samples, validated on {} held-out samples ({:.1f} s)\n", train_set.size(),
                       validation_set.size(), seconds);
    } else {
      t += fmt::format("trained on {} samples, none held out ({:.1f} s)\n", train_set.size(), seconds);
    }
    const training::ModelSelection& selection = r.report.selection;
    t += fmt::format("  model: {}\n", selection.reason);
    t += fmt::format("  image {} bytes (budget {}), Cortex-M7 forward cycle about {} instructions (budget {})\n",
                     selection.image_bytes, options.board.flash_budget_bytes, selection.forward_cycle_instructions,
                     options.board.forward_cycle_instructions);
    if (r.report.search_rows < train_set.size()) {
      t += fmt::format("  hyperparameters searched on {} of the {} rows\n", r.report.search_rows, train_set.size());
    }
    if (calibration) {
      t += fmt::format("  geometry calibrated on the {} training rows: nominal model {:.3f} mm, {:.3f} deg -> {:.3f} mm, "
                       "{:.3f} deg\n    (L, r) per segment in mm:",
                       train_set.size(), calibration->before.position_mm, calibration->before.orientation_deg,
                       calibration->after.position_mm, calibration->after.orientation_deg);
      for (int i = 0; i < geometry.segment_count; ++i) {
        t += fmt::format(" ({:.2f}, {:.2f})", geometry.segments[i].backbone_length_mm,
                         geometry.segments[i].anchor_radius_mm);
      }
      t += "\n";
    } else if (!calibration_skipped.empty()) {
      t += fmt::format("  design geometry: not calibrated ({})\n", calibration_skipped);
    }
    t += fmt::format("  encoding {}, kernel {} squared exponential, hyperparameters shared by the 6 outputs\n",
                     model::to_string(m.encoding), o.training.kernel);
    if (m.has_payload_input()) {
      t += fmt::format("  inputs: the bend vector and the payload (the last length scale; {:.3f} kg until the "
                       "runtime receives one)\n",
                       m.default_payload_kg);
    } else if (data.has_payload) {
      t += "  inputs: the bend vector; the payload_kg column is ignored (--ignore-payload)\n";
    }
    t += "  length scales (normalised inputs):";
    for (Eigen::Index i = 0; i < m.length_scales.size(); ++i) t += fmt::format(" {:.4g}", m.length_scales[i]);
    t += fmt::format("\n  signal variance {:.4g}, noise variance {:.4g} (normalised outputs)\n",
                     m.signal_variance[0], m.noise_variance[0]);
    t += fmt::format("  log marginal likelihood {:.6g} after {} evaluations\n", r.report.log_marginal_likelihood,
                     r.report.likelihood_evaluations);
    if (r.validation.samples > 0) {
      t += "held-out mean error          position (mm)   orientation (deg)\n";
      t += fmt::format("  nominal model              {:13.4f}   {:17.4f}\n", r.validation.initial.position_mm,
                       r.validation.initial.orientation_deg);
      t += fmt::format("  compensated (double)       {:13.4f}   {:17.4f}\n", r.validation.compensated.position_mm,
                       r.validation.compensated.orientation_deg);
      t += fmt::format("  compensated (float32 image){:13.4f}   {:17.4f}\n", r.firmware.compensated.position_mm,
                       r.firmware.compensated.orientation_deg);
    } else {
      t += "no held-out figures (--holdout 0): measure the image with cdcr eval on data collected apart\n";
    }
    if (validation_set.size() > 0 && o.validation_path.empty()) {
      t += fmt::format("exported model fitted on all {} rows, the held-out ones included\n", r.fitted_rows);
    }
    t += fmt::format("float32 fidelity on the {} (image path vs double trainer; target 0.01 mm, 0.001 deg):\n",
                     validation_set.size() > 0 ? "held-out samples" : "fitted rows");
    for (const auto& [accumulator, f] : r.fidelity_by_accumulator) {
      const bool firmware = accumulator != training::FirmwareAccumulator::float32;
      t += fmt::format("  {:<31} max {:.2e} mm, mean {:.2e} mm, max {:.2e} deg, mean {:.2e} deg: {}\n",
                       training::to_string(accumulator), f.max_position_mm, f.mean_position_mm,
                       f.max_orientation_deg, f.mean_orientation_deg,
                       firmware ? check_mark(training::ExportResult::meets_target(f)) : "(not used by firmware)");
    }
    t += fmt::format("wrote {} ({} bytes)\n", o.out_path, r.image.size());
    output.text = t;
  }
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
  command->add_flag("--json", o->json, "Print one JSON object");
  command->callback([o, &output] { output = run_train(*o); });
}

}  // namespace cdcr::cli
