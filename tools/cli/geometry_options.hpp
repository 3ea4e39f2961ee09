#pragma once
// The robot geometry flags shared by every command that evaluates the model:
// --length, --radius, --theta-max and --segments. The defaults describe the
// paper's prototype (Section V).

#include <optional>
#include <string>

#include <cdcr/model/geometry.hpp>

namespace CLI {
class App;
}

namespace cdcr::cli {

struct GeometryOptions {
  double backbone_length_mm = model::kPrototypeBackboneLengthMm;
  double anchor_radius_mm = model::kPrototypeAnchorRadiusMm;
  double theta_max_rad = model::kPrototypeThetaMaxRad;
  // Unset means the command decides: inferred from the input, or a default.
  std::optional<int> segment_count;
};

// segment_count_help describes what happens when --segments is omitted,
// which differs between commands.
void add_geometry_options(CLI::App& command, GeometryOptions& options, const std::string& segment_count_help);

// Uniform geometry of `segment_count` segments; throws InputError naming the
// flag whose value is not finite or out of range.
model::RobotGeometry<double> make_geometry(const GeometryOptions& options, int segment_count);

}  // namespace cdcr::cli
