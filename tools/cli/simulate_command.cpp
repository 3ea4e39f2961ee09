#include "simulate_command.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_errors.hpp"
#include "dataset/csv_dataset.hpp"
#include "json_output.hpp"
#include "number_list.hpp"
#include "sim/data_collection.hpp"

#include <cdcr/model/hysteresis.hpp>
#include <cdcr/model/units.hpp>

namespace cdcr::cli {
namespace {

const char* on_off(bool enabled) { return enabled ? "on" : "off"; }

std::uint64_t parse_seed(const std::string& text) {
  const bool negative = !text.empty() && text.front() == '-';
  const std::string_view digits = negative ? std::string_view(text).substr(1) : std::string_view(text);
  std::uint64_t seed = 0;
  const auto [stop, error] = std::from_chars(digits.data(), digits.data() + digits.size(), seed);
  if (digits.empty() || stop != digits.data() + digits.size() ||
      (error != std::errc() && error != std::errc::result_out_of_range)) {
    throw UsageError(fmt::format("--seed: '{}' is not an integer", text));
  }
  if (negative) throw InputError(fmt::format("--seed must not be negative (got {})", text));
  if (error == std::errc::result_out_of_range) {
    throw InputError(
        fmt::format("--seed must not exceed {} (got {})", std::numeric_limits<std::uint64_t>::max(), text));
  }
  return seed;
}

sim::PayloadConfig parse_payload_range(const std::string& text) {
  const std::vector<double> range = parse_number_list(text, "--payload-range");
  require_count(range, 2, "--payload-range", "LO,HI in kg");
  require_finite(range, "--payload-range");
  if (range[0] < 0.0) throw InputError(fmt::format("--payload-range: LO must not be negative (got {} kg)", range[0]));
  if (range[0] > range[1]) {
    throw InputError(fmt::format("--payload-range: LO must not exceed HI (got {} > {} kg)", range[0], range[1]));
  }
  sim::PayloadConfig payload;
  payload.enabled = true;
  payload.min_kg = range[0];
  payload.max_kg = range[1];
  return payload;
}

sim::SimulatorConfig make_config(const SimulateCommandOptions& options, const model::RobotGeometry<double>& geometry,
                                std::uint64_t seed) {
  sim::SimulatorConfig config;
  config.seed = seed;
  if (options.session < 0) throw InputError(fmt::format("--session must not be negative (got {})", options.session));
  config.session = static_cast<std::uint64_t>(options.session);
  if (options.workspace_theta_max_rad) {
    const double theta_max_rad = *options.workspace_theta_max_rad;
    if (!std::isfinite(theta_max_rad)) {
      throw InputError(fmt::format("--workspace-theta-max must be a finite number (got {})", theta_max_rad));
    }
    if (!(theta_max_rad > 0.0)) {
      throw InputError(fmt::format("--workspace-theta-max must be positive (got {} rad)", theta_max_rad));
    }
    config.workspace_theta_max_rad = theta_max_rad;
  }
  const double design_theta_max_rad = geometry.segments[0].theta_max_rad;
  if (!options.workspace_theta_max_rad) {
    config.workspace_theta_max_rad = std::min(config.workspace_theta_max_rad, design_theta_max_rad);
  } else if (config.workspace_theta_max_rad > design_theta_max_rad) {
    throw InputError(fmt::format("--workspace-theta-max ({} rad) exceeds --theta-max ({} rad)",
                                 config.workspace_theta_max_rad, design_theta_max_rad));
  }
  // The session noise first: --noise-scale and the --no-* switches apply to it.
  if (options.hysteresis) {
    if (options.payload_range_kg) {
      throw InputError("--hysteresis records a motion sequence (a t_s column), which cannot carry a payload column: "
                       "drop --payload-range");
    }
    config.use_hysteresis_session();
    if (options.hysteresis_lag_mm) {
      const std::vector<double> range = parse_number_list(*options.hysteresis_lag_mm, "--hysteresis-lag");
      require_count(range, 2, "--hysteresis-lag", "LO,HI in mm");
      require_finite(range, "--hysteresis-lag");
      if (!(range[0] >= 0.0 && range[0] <= range[1])) {
        throw InputError(fmt::format("--hysteresis-lag must satisfy 0 <= LO <= HI (got {}, {} mm)", range[0], range[1]));
      }
      config.hysteresis.max_lag_min_mm = range[0];
      config.hysteresis.max_lag_max_mm = range[1];
    }
  } else if (options.hysteresis_lag_mm) {
    throw InputError("--hysteresis-lag needs --hysteresis");
  }
  config.geometric.enabled = !options.no_geometric;
  config.curvature.enabled = !options.no_curvature;
  config.compliance.enabled = !options.no_compliance;
  config.gravity.enabled = !options.no_gravity;
  config.repeatability.enabled = !options.no_repeatability;
  config.mocap_noise.enabled = !options.no_mocap_noise;
  if (!std::isfinite(options.noise_scale) || options.noise_scale < 0.0) {
    throw InputError(fmt::format("--noise-scale must be a finite number, zero or more (got {})", options.noise_scale));
  }
  config.repeatability.bend_sigma_rad *= options.noise_scale;
  config.mocap_noise.position_sigma_mm *= options.noise_scale;
  config.mocap_noise.rotation_sigma_rad *= options.noise_scale;
  if (options.payload_range_kg) config.payload = parse_payload_range(*options.payload_range_kg);
  return config;
}

dataset::Dataset to_dataset(const std::vector<sim::CollectedSample>& samples,
                            const model::RobotGeometry<double>& geometry, bool payload, bool sequence) {
  dataset::Dataset data;
  data.segment_count = geometry.segment_count;
  for (int i = 0; i < geometry.segment_count; ++i) data.segment_cables.push_back(geometry.segments[i].cables.count);
  data.has_poses = true;
  data.has_payload = payload;
  data.cables_mm.resize(static_cast<Eigen::Index>(samples.size()), geometry.cable_count());
  if (payload) data.payload_kg.resize(static_cast<Eigen::Index>(samples.size()));
  data.poses.reserve(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    data.cables_mm.row(static_cast<Eigen::Index>(i)) = samples[i].cables_mm.transpose();
    if (payload) data.payload_kg[static_cast<Eigen::Index>(i)] = samples[i].payload_kg;
    data.poses.push_back(samples[i].measurement.measured_pose);
  }
  if (sequence) {
    data.has_time = true;
    data.time_s.resize(static_cast<Eigen::Index>(samples.size()));
    for (std::size_t i = 0; i < samples.size(); ++i) data.time_s[static_cast<Eigen::Index>(i)] = samples[i].time_s;
    data.session_starts = dataset::session_starts_from_times(data.time_s);
  }
  return data;
}

std::string payload_comment(const sim::SimulatorConfig& config) {
  if (!config.payload.enabled) return {};
  return fmt::format("payload: uniform in [{}, {}] kg per sample (column payload_kg), {}\n", config.payload.min_kg,
                     config.payload.max_kg,
                     config.gravity.enabled
                         ? fmt::format("on top of the {} kg end platform", config.gravity.platform_mass_kg)
                         : std::string("weightless: gravity is off"));
}

std::string hysteresis_comment(const sim::SimulatorConfig& config, const sim::CollectionSummary& summary) {
  if (!config.hysteresis.enabled) return {};
  const sim::HysteresisConfig& h = config.hysteresis;
  return fmt::format(
      "hysteresis: per cable a maximum lag uniform in [{}, {}] mm ({} play operators); the robot's state before "
      "homing is unknown\n"
      "motion sequence (column t_s, s from the end of the homing move): homing move (every segment bent {} rad "
      "towards alpha = 45 deg, then straight), then row to row along straight lines in cable space at {} mm/s, "
      "settling {} s before each row\n"
      "noise: repeatability sigma {} rad, mocap {} mm, {} deg\n"
      "hysteresis moves the tip (same commands without it): mean {:.6g} mm, max {:.6g} mm\n",
      h.max_lag_min_mm, h.max_lag_max_mm, sim::HysteresisConfig::kOperators, model::kHomingBendRad,
      config.motion.cable_speed_mm_per_s, config.motion.settle_s,
      config.repeatability.enabled ? config.repeatability.bend_sigma_rad : 0.0,
      config.mocap_noise.enabled ? config.mocap_noise.position_sigma_mm : 0.0,
      config.mocap_noise.enabled ? config.mocap_noise.rotation_sigma_rad * model::kDegreesPerRadian : 0.0,
      summary.hysteresis.mean_position_mm, summary.hysteresis.max_position_mm);
}

std::string dataset_comment(const model::RobotGeometry<double>& geometry,
                            const sim::SimulatorConfig& config, const sim::CollectionSummary& summary) {
  const model::SegmentGeometry<double>& segment = geometry.segments[0];
  return fmt::format(
             "simulated robot (cdcr simulate): seed {}, session {}, {} samples\n"
             "geometry: {} segments, L = {} mm, r = {} mm, theta_max = {} rad; workspace theta_max = {} rad\n"
             "error sources: geometric {}, curvature {}, compliance {}, gravity {}, repeatability {}, mocap-noise {}\n",
             config.seed, config.session, summary.samples, geometry.segment_count, segment.backbone_length_mm,
             segment.anchor_radius_mm, segment.theta_max_rad, config.workspace_theta_max_rad,
             on_off(config.geometric.enabled), on_off(config.curvature.enabled), on_off(config.compliance.enabled),
             on_off(config.gravity.enabled), on_off(config.repeatability.enabled),
             on_off(config.mocap_noise.enabled)) +
         payload_comment(config) + hysteresis_comment(config, summary) +
         fmt::format("initial mean error (nominal model vs measured): {:.6g} mm, {:.6g} deg\n",
                     summary.initial.position_mm, summary.initial.orientation_deg) +
         fmt::format("noise floor (true vs measured pose): {:.6g} mm, {:.6g} deg", summary.noise_floor.position_mm,
                     summary.noise_floor.orientation_deg);
}

}  // namespace

void register_simulate_command(CLI::App& app, CommandOutput& output) {
  auto options = std::make_shared<SimulateCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "simulate", "Generate a dataset from the simulated robot (random workspace samples, measured poses)");
  command->add_option("--samples", options->samples, "Number of samples")->capture_default_str();
  command->add_option("--seed", options->seed, "Seed: a given seed is a given physical robot and data set")
      ->type_name("UINT")
      ->capture_default_str();
  command->add_option("--session", options->session,
                      "Data-collection session on the same robot: another session gives an independent test set")
      ->capture_default_str();
  command->add_option("--out", options->out_path, "Write the dataset CSV to this file")->type_name("FILE");
  command->add_option("--workspace-theta-max", options->workspace_theta_max_rad,
                      fmt::format("Upper limit of the sampled bending angles (rad, default {} or --theta-max if smaller)",
                                  sim::SimulatorConfig{}.workspace_theta_max_rad))
      ->type_name("RAD");
  add_geometry_options(*command, options->geometry, "Number of segments (default: 4)");
  command->add_flag("--no-geometric", options->no_geometric, "Without geometric and mounting errors");
  command->add_flag("--no-curvature", options->no_curvature, "Constant-curvature segments");
  command->add_flag("--no-compliance", options->no_compliance, "Inextensible cables");
  command->add_flag("--no-gravity", options->no_gravity, "Without gravity sag");
  command->add_flag("--no-repeatability", options->no_repeatability, "Without repeatability noise");
  command->add_flag("--no-mocap-noise", options->no_mocap_noise, "Without motion-capture noise");
  command->add_option("--noise-scale", options->noise_scale,
                      "Scale of the per-sample noise (repeatability and motion capture); 0.25 is a low-noise robot")
      ->capture_default_str();
  command->add_option("--payload-range", options->payload_range_kg,
                      "Payload on the end platform, drawn per sample uniform in [LO, HI] kg; writes the payload_kg "
                      "column")
      ->type_name("LO,HI");
  command->add_flag("--hysteresis", options->hysteresis,
                    fmt::format("With cable friction hysteresis (maximum lag {}-{} mm per cable) and a low-noise "
                                "session (repeatability {} rad, mocap {} mm, {} deg): records a motion sequence that "
                                "starts with the homing move, with a t_s column",
                                sim::HysteresisConfig{}.max_lag_min_mm, sim::HysteresisConfig{}.max_lag_max_mm,
                                sim::HysteresisSessionDefaults::kRepeatabilitySigmaRad,
                                sim::HysteresisSessionDefaults::kMocapPositionSigmaMm,
                                sim::HysteresisSessionDefaults::kMocapRotationSigmaRad * model::kDegreesPerRadian));
  command->add_option("--hysteresis-lag", options->hysteresis_lag_mm,
                      "With --hysteresis: the range every cable's maximum lag is drawn from, mm")
      ->type_name("LO,HI");
  command->add_flag("--json", options->json, "Print one JSON object instead of the summary");
  command->callback([options, &output] { output = run_simulate(*options); });
}

CommandOutput run_simulate(const SimulateCommandOptions& options) {
  const std::uint64_t seed = parse_seed(options.seed);
  if (options.samples < 1 || options.samples > kMaxSimulateSampleCount) {
    throw InputError(
        fmt::format("--samples must be between 1 and {} (got {})", kMaxSimulateSampleCount, options.samples));
  }
  const model::RobotGeometry<double> geometry =
      make_geometry(options.geometry, options.geometry.segment_count.value_or(model::kPrototypeSegmentCount));
  const sim::SimulatorConfig config = make_config(options, geometry, seed);

  std::vector<sim::CollectedSample> samples;
  try {
    sim::SimulatedRobot robot(geometry, config);
    samples = sim::collect(robot, options.samples);
  } catch (const std::invalid_argument& error) {
    throw InputError(error.what());
  }
  const sim::CollectionSummary summary = sim::summarize(samples);

  if (options.out_path) {
    try {
      const dataset::Dataset data =
          to_dataset(samples, geometry, config.payload.enabled, summary.sequence);
      dataset::write_dataset_csv(*options.out_path, data, dataset_comment(geometry, config, summary));
    } catch (const dataset::DatasetError& error) {
      throw InputError(error.what());
    }
  }

  CommandOutput output;
  if (options.json) {
    Json result;
    result["samples"] = summary.samples;
    result["initial"] = {{"position_mm", summary.initial.position_mm},
                         {"orientation_deg", summary.initial.orientation_deg}};
    result["noise_floor"] = {{"position_mm", summary.noise_floor.position_mm},
                             {"orientation_deg", summary.noise_floor.orientation_deg}};
    if (config.payload.enabled) result["payload_kg"] = {{"min", config.payload.min_kg}, {"max", config.payload.max_kg}};
    if (summary.sequence) {
      result["hysteresis"] = {{"mean_position_mm", summary.hysteresis.mean_position_mm},
                              {"max_position_mm", summary.hysteresis.max_position_mm},
                              {"mean_orientation_deg", summary.hysteresis.mean_orientation_deg},
                              {"max_orientation_deg", summary.hysteresis.max_orientation_deg}};
      result["duration_s"] = samples.back().time_s;
    }
    output.text = result.dump() + "\n";
  } else {
    output.text = fmt::format("samples: {}\n", summary.samples);
    if (config.payload.enabled) {
      output.text +=
          fmt::format("payload: {} to {} kg, uniform per sample\n", config.payload.min_kg, config.payload.max_kg);
    }
    output.text += fmt::format("initial mean error: {:.3f} mm, {:.3f} deg\nnoise floor: {:.3f} mm, {:.3f} deg\n",
                               summary.initial.position_mm, summary.initial.orientation_deg,
                               summary.noise_floor.position_mm, summary.noise_floor.orientation_deg);
    if (summary.sequence) {
      output.text += fmt::format(
          "hysteresis moves the tip (against the same commands without it): mean {:.3f} mm, max {:.3f} mm; "
          "{:.3f} deg, {:.3f} deg\nmotion sequence: homing move, then {} rows in {:.1f} s\n",
          summary.hysteresis.mean_position_mm, summary.hysteresis.max_position_mm,
          summary.hysteresis.mean_orientation_deg, summary.hysteresis.max_orientation_deg, summary.samples,
          samples.back().time_s);
    }
    if (options.out_path) output.text += fmt::format("dataset: {}\n", *options.out_path);
  }
  return output;
}

}  // namespace cdcr::cli
