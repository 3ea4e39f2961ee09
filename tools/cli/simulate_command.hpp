#pragma once
// cdcr simulate: a dataset from the simulated robot, collected as in the
// paper's experiment (Section V-B): random joint variables, cables commanded
// through the nominal inverse, the end-platform pose as the motion-capture
// system reports it. With --hysteresis, a motion sequence: the homing move,
// then row to row along straight lines in cable space, with a t_s column.

#include <cstdint>
#include <optional>
#include <string>

#include "command_output.hpp"
#include "geometry_options.hpp"

namespace CLI {
class App;
}

namespace cdcr::cli {

inline constexpr int kDefaultSimulateSampleCount = 750;  // the paper's data set
inline constexpr int kMaxSimulateSampleCount = 1000000;

struct SimulateCommandOptions {
  GeometryOptions geometry;
  int samples = kDefaultSimulateSampleCount;
  // Text until run_simulate parses it: the whole uint64 range is valid, and a
  // negative or too large value must be refused rather than wrapped or clamped.
  std::string seed = "1";
  int session = 0;
  std::optional<double> workspace_theta_max_rad;  // unset: the simulator's default
  std::optional<std::string> out_path;            // unset: summary only
  bool no_geometric = false;
  bool no_curvature = false;
  bool no_compliance = false;
  bool no_gravity = false;
  bool no_repeatability = false;
  bool no_mocap_noise = false;
  double noise_scale = 1.0;
  std::optional<std::string> payload_range_kg;  // "LO,HI"; unset: no payload, no payload column
  // Cable friction hysteresis (source 7) with the session noise of
  // sim::HysteresisSessionDefaults; the dataset is a motion sequence (t_s).
  bool hysteresis = false;
  std::optional<std::string> hysteresis_lag_mm;  // "LO,HI": the range of every cable's maximum lag; needs hysteresis
  bool json = false;
};

// Adds the `simulate` subcommand; when it is selected, parsing stores its result in `output`.
void register_simulate_command(CLI::App& app, CommandOutput& output);

CommandOutput run_simulate(const SimulateCommandOptions& options);

}  // namespace cdcr::cli
