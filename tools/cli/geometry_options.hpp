#pragma once
// The robot geometry flags shared by every command that evaluates the model:
// --length, --radius, --theta-max, --segments, and the cables:
// --cables-per-segment and --cable-angles. The defaults describe the paper's prototype (Section V).

#include <optional>
#include <string>
#include <vector>

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
  // Cables per segment (3 or 4); unset: a dataset's columns, the angles'
  // count, or four.
  std::optional<int> cables_per_segment;
  // Each cable's anchor angle in the segment's base frame (degrees), the
  // same for every segment; empty: evenly spaced, cable 1 on the x axis and
  // the others clockwise (the paper's four at 0, -90, -180, -270).
  std::vector<double> cable_angles_deg;
};

// segment_count_help describes what happens when --segments is omitted,
// which differs between commands.
void add_geometry_options(CLI::App& command, GeometryOptions& options, const std::string& segment_count_help);

// Uniform geometry of `segment_count` segments, each with the cables the
// flags give, or a dataset's (`segment_cables`, one count per segment);
// throws InputError naming the flag whose value is not finite, out of
// range or at odds with the dataset.
model::RobotGeometry<double> make_geometry(const GeometryOptions& options, int segment_count,
                                           const std::vector<int>& segment_cables = {});

// The cables of a segment the flags give (without a dataset): 3 or 4.
int cables_per_segment(const GeometryOptions& options);

}  // namespace cdcr::cli
