#include "training_commands.hpp"

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cdcr/model/compensated_kinematics.hpp"
#include "cdcr/model/hysteresis_sequence.hpp"
#include "cdcr/model/image_hysteresis.hpp"
#include "cdcr/model/units.hpp"
#include "cli_errors.hpp"
#include "export/binary_file.hpp"
#include "dataset_input.hpp"
#include "image_input.hpp"
#include "json_output.hpp"
#include "power_up_estimates.hpp"
#include "train/evaluation.hpp"
#include "train/training_set.hpp"

namespace cdcr::cli {
namespace {

struct EvalCommandOptions {
  std::string model_path;
  std::string data_path;
  std::string rows_path;
  bool json = false;
  // The first session starts at power-up with the hysteresis state unknown
  // (no homing), as the board does; its first `first_rows` rows are
  // reported apart.
  bool from_power_up = false;
  int first_rows = 20;
};

Json coverage_json(const training::CoverageCheck& c) {
  return {{"rows", c.samples},
          {"r95_mm", c.position_coverage},
          {"r95_deg", c.orientation_coverage},
          {"median_r95_mm", c.median_r95_mm},
          {"median_r95_deg", c.median_r95_deg}};
}

// The coverage of rows [begin, end), or none for an empty range.
training::CoverageCheck coverage_of(const std::vector<model::Pose<double>>& measured,
                                    const std::vector<training::FirmwareEstimate>& estimates, int begin, int end) {
  if (begin >= end) return training::CoverageCheck{};
  return training::check_coverage({measured.begin() + begin, measured.begin() + end},
                                   {estimates.begin() + begin, estimates.begin() + end});
}

// One line per sample: its bend angles, errors, radii and flags, for plots
// and for checks that need the rows (written atomically).
void write_rows(const std::string& path, const training::TrainingSet& set,
                const std::vector<training::FirmwareEstimate>& estimates) {
  const int segments = static_cast<int>(set.bends.cols()) / 2;
  std::string text;
  for (int s = 0; s < segments; ++s) text += fmt::format("theta_{},", s + 1);
  text += "position_error_mm,orientation_error_deg,r95_mm,r95_deg,latent_share,outside_range,extrapolating\n";
  for (int i = 0; i < set.size(); ++i) {
    for (int s = 0; s < segments; ++s) text += fmt::format("{:.6g},", set.bends.row(i).segment<2>(2 * s).norm());
    const model::PoseError<double> e = model::pose_error(set.measured[i], estimates[i].pose);
    const model::PoseUncertainty<double>& u = estimates[i].uncertainty;
    text += fmt::format("{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{},{}\n", e.position_mm,
                        e.orientation_rad * model::kDegreesPerRadian, u.r95_mm, u.r95_deg, u.latent_share,
                        u.outside_range ? 1 : 0, u.extrapolating ? 1 : 0);
  }
  exporting::write_binary_file(path, text.data(), text.size());
}

// What the board's hysteresis state gives the rows, a motion sequence: the
// image's block in float32, each session starting at home, the state carried
// from row to row.
struct BoardSequence {
  Eigen::MatrixXd effective_mm;
  Eigen::MatrixXd history;  // where each cable last moved; empty unless the image takes it
};

BoardSequence board_sequence(const model::ImageView& image, const model::HysteresisModel<float>& hysteresis,
                             const Eigen::MatrixXd& cables_mm, const std::vector<int>& session_starts) {
  model::RobotGeometry<float> geometry;
  model::geometry_from_image(image, geometry);
  Eigen::MatrixXf effective(cables_mm.rows(), cables_mm.cols()), history(cables_mm.rows(), cables_mm.cols());
  const bool with_history = model::takes_history(image.encoding);
  if (const model::Status s = model::effective_lengths_over_sequence(
          hysteresis, geometry, cables_mm, session_starts.data(), static_cast<int>(session_starts.size()), effective,
          model::SessionStart::homed, with_history ? &history : nullptr);
      s != model::Status::ok) {
    throw std::invalid_argument(std::string("hysteresis: ") + model::to_string(s));
  }
  return {effective.cast<double>(), with_history ? Eigen::MatrixXd(history.cast<double>()) : Eigen::MatrixXd()};
}

// What the image and the rows hold, checked against each other before any
// row is evaluated.
struct EvalInputs {
  LoadedImage image;
  dataset::Dataset data;
  model::RobotGeometry<double> geometry;
  bool payload_input = false;
  model::HysteresisModel<float> hysteresis;
  bool with_hysteresis = false;
};

EvalInputs load_eval_inputs(const EvalCommandOptions& o) {
  EvalInputs in;
  in.image = load_image(o.model_path);
  in.data = load_dataset(o.data_path, true);
  const dataset::Dataset& data = in.data;
  if (const model::Status s = model::geometry_from_image(in.image.view, in.geometry); s != model::Status::ok) {
    throw InputError(fmt::format("{}: geometry: {}", o.model_path, model::to_string(s)));
  }
  if (data.segment_count != in.geometry.segment_count) {
    throw InputError(fmt::format("{} has {} segments but the model has {}", o.data_path, data.segment_count,
                                 in.geometry.segment_count));
  }
  // A payload model needs the column; a model without the input runs on
  // the cables alone and the column is ignored (the output says so).
  in.payload_input = in.image.view.extra_inputs > 0;
  if (in.payload_input && !data.has_payload) {
    throw InputError(fmt::format("{}: the model takes a payload input and the data have no payload_kg column",
                                 o.data_path));
  }
  // A model of the cables' hysteresis needs the rows' order and sessions:
  // rows without a time column are independent samples.
  if (o.from_power_up && !data.has_time) {
    throw InputError(fmt::format("{}: --from-power-up needs a motion sequence (a t_s column), but the rows have no time",
                                 o.data_path));
  }
  in.with_hysteresis = model::hysteresis_from_image(in.image.view, in.hysteresis);
  if (o.from_power_up && !in.with_hysteresis) {
    throw InputError(fmt::format("{}: --from-power-up needs an image with a hysteresis block", o.model_path));
  }
  if (in.with_hysteresis && !data.has_time) {
    throw InputError(fmt::format("{}: the model compensates the cables' hysteresis and needs a motion sequence (a t_s "
                                 "column), but the rows have no time",
                                 o.data_path));
  }
  return in;
}

// The rows through the board's path, and what is reported of them.
struct EvalResults {
  training::TrainingSet set;
  std::vector<model::Pose<double>> compensated;
  std::vector<training::FirmwareEstimate> estimates;
  PowerUpEstimates power_up;
  training::MeanErrors initial, after;
  bool has_variance = false;
  training::CoverageCheck coverage, first_coverage, rest_coverage;
  bool report_power_up = false;
};

EvalResults evaluate(const EvalCommandOptions& o, const EvalInputs& in) {
  EvalResults r;
  const model::ImageView& view = in.image.view;
  try {
    r.set = training::make_training_set(in.data, in.geometry, model::with_history(view.encoding, false),
                                        in.payload_input);
    // The nominal (initial) error stays that of the commanded lengths.
    const BoardSequence sequence =
        in.with_hysteresis ? board_sequence(view, in.hysteresis, r.set.cables_mm, in.data.session_starts)
                           : BoardSequence{r.set.cables_mm, Eigen::MatrixXd()};
    const Eigen::MatrixXd& cables_mm = sequence.effective_mm;
    const Eigen::MatrixXd& history = sequence.history;
    r.compensated = training::firmware_poses(view, cables_mm, training::FirmwareAccumulator::float64,
                                             r.set.payload_kg, history);
    r.estimates = training::firmware_estimates(view, cables_mm, r.set.payload_kg, history);
    if (o.from_power_up) {
      // The first session again, from power-up: the board's own path.
      const Eigen::Index first_session_rows =
          in.data.session_starts.size() > 1 ? in.data.session_starts[1] : r.set.cables_mm.rows();
      r.power_up = estimates_from_power_up(view, r.set.cables_mm.topRows(first_session_rows));
      for (std::size_t i = 0; i < r.power_up.estimates.size(); ++i) {
        r.estimates[i] = r.power_up.estimates[i];
        r.compensated[i] = r.power_up.estimates[i].pose;
      }
    }
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: {}", o.data_path, e.what()));
  }
  r.initial = training::mean_errors(r.set.measured, r.set.nominal);
  r.after = training::mean_errors(r.set.measured, r.compensated);
  r.has_variance = view.variance_rank > 0;
  r.coverage = training::check_coverage(r.set.measured, r.estimates);
  const int first_rows = std::min(o.first_rows, r.set.size());
  r.first_coverage = coverage_of(r.set.measured, r.estimates, 0, first_rows);
  r.rest_coverage = coverage_of(r.set.measured, r.estimates, first_rows, r.set.size());
  r.report_power_up = o.from_power_up && r.has_variance;
  return r;
}

const char* payload_use(const EvalInputs& in) {
  return in.payload_input ? "used" : (in.data.has_payload ? "ignored" : "none");
}

std::string eval_json(const EvalCommandOptions& o, const EvalInputs& in, const EvalResults& r) {
  Json j;
  j["n"] = r.set.size();
  j["initial"] = {{"position_mm", r.initial.position_mm}, {"orientation_deg", r.initial.orientation_deg}};
  j["compensated"] = {{"position_mm", r.after.position_mm}, {"orientation_deg", r.after.orientation_deg}};
  j["extrapolating"] = r.coverage.extrapolating;
  j["outside_range"] = r.coverage.outside_range;
  j["payload"] = payload_use(in);
  j["hysteresis"] = o.from_power_up      ? "carried over the sequence, the first session from power-up"
                    : in.with_hysteresis ? "carried over the sequence"
                                         : "none";
  if (o.from_power_up) {
    j["power_up"] = {{"unknown_rows", r.power_up.unknown_rows},
                     {"first_rows", r.report_power_up ? coverage_json(r.first_coverage) : Json(nullptr)},
                     {"later_rows", r.report_power_up && r.rest_coverage.samples > 0 ? coverage_json(r.rest_coverage)
                                                                                     : Json(nullptr)}};
  }
  if (r.has_variance) {
    j["coverage"] = {{"r95_mm", r.coverage.position_coverage},
                     {"r95_deg", r.coverage.orientation_coverage},
                     {"median_r95_mm", r.coverage.median_r95_mm},
                     {"median_r95_deg", r.coverage.median_r95_deg},
                     {"median_latent_share", r.coverage.median_latent_share}};
  } else {
    j["coverage"] = nullptr;
  }
  return j.dump() + "\n";
}

std::string eval_text(const EvalCommandOptions& o, const EvalInputs& in, const EvalResults& r) {
  const training::CoverageCheck& coverage = r.coverage;
  std::string text = fmt::format(
      "{} samples                position (mm)   orientation (deg)\n"
      "  initial (nominal)    {:13.4f}   {:17.4f}\n"
      "  compensated          {:13.4f}   {:17.4f}\n",
      r.set.size(), r.initial.position_mm, r.initial.orientation_deg, r.after.position_mm, r.after.orientation_deg);
  if (r.has_variance) {
    text += fmt::format("  within r95           {:12.1f}%   {:16.1f}%   (median r95 {:.3f} mm, {:.4f} deg)\n",
                        100.0 * coverage.position_coverage, 100.0 * coverage.orientation_coverage,
                        coverage.median_r95_mm, coverage.median_r95_deg);
  } else {
    text += "  within r95           the image carries no variance\n";
  }
  text += fmt::format("  extrapolating        {} of {} samples ({} outside the fitted input range)\n",
                      coverage.extrapolating, r.set.size(), coverage.outside_range);
  const std::size_t sessions = std::max<std::size_t>(1, in.data.session_starts.size());
  if (o.from_power_up) {
    text += fmt::format(
        "  hysteresis           carried from row to row over {} session(s), the first from power-up (state unknown "
        "for its first {} rows, r95 widened){}\n",
        sessions, r.power_up.unknown_rows, in.data.session_starts.size() > 1 ? ", the others from home" : "");
    if (r.report_power_up) {
      text += fmt::format("  within r95, first {:3} rows {:6.1f}%   {:16.1f}%   (median r95 {:.3f} mm, {:.4f} deg)\n",
                          r.first_coverage.samples, 100.0 * r.first_coverage.position_coverage,
                          100.0 * r.first_coverage.orientation_coverage, r.first_coverage.median_r95_mm,
                          r.first_coverage.median_r95_deg);
    }
    if (r.report_power_up && r.rest_coverage.samples > 0) {
      text += fmt::format("  within r95, later rows  {:9.1f}%   {:16.1f}%   (median r95 {:.3f} mm, {:.4f} deg)\n",
                          100.0 * r.rest_coverage.position_coverage, 100.0 * r.rest_coverage.orientation_coverage,
                          r.rest_coverage.median_r95_mm, r.rest_coverage.median_r95_deg);
    }
  } else if (in.with_hysteresis) {
    text += fmt::format("  hysteresis           carried from row to row over {} session(s), each from home\n",
                        sessions);
  }
  if (in.data.has_payload && !in.payload_input) {
    text += "  payload              the payload_kg column is ignored: the model has no payload input\n";
  } else if (in.payload_input) {
    text += "  payload              each sample's payload_kg is the model's payload input\n";
  }
  return text;
}

CommandOutput run_eval(const EvalCommandOptions& o) {
  const EvalInputs in = load_eval_inputs(o);
  const EvalResults results = evaluate(o, in);
  if (!o.rows_path.empty()) write_rows(o.rows_path, results.set, results.estimates);
  CommandOutput output;
  output.text = o.json ? eval_json(o, in, results) : eval_text(o, in, results);
  return output;
}

}  // namespace

void register_eval_command(CLI::App& app, CommandOutput& output) {
  auto o = std::make_shared<EvalCommandOptions>();
  CLI::App* command = app.add_subcommand("eval", "Mean tip errors before and after compensation by a model image");
  command->add_option("--model", o->model_path, "Flash image written by cdcr train")->required();
  command->add_option("--data", o->data_path, "Dataset CSV with measured poses")->required();
  command->add_option("--rows", o->rows_path,
                      "Also write one CSV line per sample: bend angles, errors, r95 radii, latent share and flags");
  command->add_flag("--json", o->json, "Print one JSON object");
  command->add_flag("--from-power-up", o->from_power_up,
                    "Start the first session at power-up with the hysteresis state unknown (no homing), widening r95 "
                    "as the board does; needs a t_s column and a hysteresis image");
  command->add_option("--first-rows", o->first_rows,
                      "With --from-power-up: the rows whose r95 coverage is reported apart (default 20)")
      ->check(CLI::Range(1, 1000000));
  command->callback([o, &output] { output = run_eval(*o); });
}

}  // namespace cdcr::cli
