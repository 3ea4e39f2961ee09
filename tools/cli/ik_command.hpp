#pragma once
// cdcr ik: target tip position or pose -> joint variables and cable lengths,
// by the model's damped least-squares solver.

#include <optional>
#include <string>

#include "command_output.hpp"
#include "geometry_options.hpp"

namespace CLI {
class App;
}

namespace cdcr::cli {

// Unlike fk, ik has nothing to infer the segment count from.
inline constexpr int kDefaultIkSegmentCount = model::kPrototypeSegmentCount;
// The number lists stay text until run_ik parses them; unset means the flag
// was not given.
struct IkCommandOptions {
  GeometryOptions geometry;
  std::optional<std::string> position_mm;     // X,Y,Z
  std::optional<std::string> quaternion;      // QW,QX,QY,QZ, only with position_mm
  std::optional<std::string> pose;            // 12 or 16 row-major values, instead of the two above
  std::optional<std::string> initial_joints;  // alpha_1,theta_1,alpha_2,theta_2,... in rad
  std::optional<int> max_iterations;  // unset: the runtime's bound
  bool json = false;
};

// Adds the `ik` subcommand; when it is selected, parsing stores its result in `output`.
void register_ik_command(CLI::App& app, CommandOutput& output);

CommandOutput run_ik(const IkCommandOptions& options);

}  // namespace cdcr::cli
