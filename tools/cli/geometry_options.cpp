#include "geometry_options.hpp"

#include <cmath>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_errors.hpp"

namespace cdcr::cli {
namespace {

constexpr double kPi = 3.14159265358979323846;

void require_positive(double value, const char* flag, const char* unit) {
  if (!std::isfinite(value)) throw InputError(fmt::format("{} must be a finite number (got {})", flag, value));
  if (!(value > 0.0)) throw InputError(fmt::format("{} must be positive (got {} {})", flag, value, unit));
}

}  // namespace

void add_geometry_options(CLI::App& command, GeometryOptions& options, const std::string& segment_count_help) {
  command.add_option("--length", options.backbone_length_mm, "Backbone length L of each segment (mm)")
      ->capture_default_str();
  command.add_option("--radius", options.anchor_radius_mm, "Radius r of the cable anchor circle (mm)")
      ->capture_default_str();
  command.add_option("--theta-max", options.theta_max_rad, "Upper limit of each segment's bending angle (rad)")
      ->capture_default_str();
  command.add_option("--segments", options.segment_count, segment_count_help)->type_name("INT");
  command.add_option("--cables-per-segment", options.cables_per_segment,
                     "Cables per segment, 3 or 4 (default: the dataset's columns, else 4)")
      ->type_name("INT");
  command.add_option("--cable-angles", options.cable_angles_deg,
                     "Anchor angle of each cable in the segment's base frame (deg), the same for every segment "
                     "(default: evenly spaced, cable 1 at 0 and the others clockwise: 0,-90,-180,-270 for four)")
      ->delimiter(',')
      ->type_name("DEG,...");
}

namespace {

// Where the flags and a dataset agree, the layout of a segment of `count`
// cables.
model::CableLayout<double> layout_for(const GeometryOptions& options, int count) {
  const std::vector<double>& degrees = options.cable_angles_deg;
  if (degrees.empty()) return model::CableLayout<double>::evenly_spaced(count);
  if (static_cast<int>(degrees.size()) != count) {
    throw InputError(fmt::format("--cable-angles gives {} angles for segments of {} cables", degrees.size(), count));
  }
  double psi[model::kMaxCablesPerSegment] = {};
  for (int j = 0; j < count; ++j) {
    if (!std::isfinite(degrees[j])) {
      throw InputError(fmt::format("--cable-angles must be finite numbers (got {})", degrees[j]));
    }
    psi[j] = degrees[j] * kPi / 180.0;
  }
  const auto layout = model::CableLayout<double>::at_angles(count, psi);
  if (layout.validate() != model::Status::ok) {
    throw InputError(fmt::format("--cable-angles: anchors this close to one line cannot read a bend across it "
                                 "(spread {:.3f}, at least {})",
                                 layout.spread(), model::CableLayout<double>::kLeastAnchorSpread));
  }
  return layout;
}

int cables_for(const GeometryOptions& options, const std::vector<int>& segment_cables, int segment) {
  if (options.cables_per_segment &&
      (*options.cables_per_segment < model::kMinCablesPerSegment ||
       *options.cables_per_segment > model::kMaxCablesPerSegment)) {
    throw InputError(fmt::format("--cables-per-segment must be {} or {} (got {})", model::kMinCablesPerSegment,
                                 model::kMaxCablesPerSegment, *options.cables_per_segment));
  }
  if (!segment_cables.empty()) {
    const int columns = segment_cables[static_cast<std::size_t>(segment)];
    if (options.cables_per_segment && *options.cables_per_segment != columns) {
      throw InputError(fmt::format("--cables-per-segment is {} but the dataset's segment {} has {} cable columns",
                                   *options.cables_per_segment, segment + 1, columns));
    }
    return columns;
  }
  if (options.cables_per_segment) return *options.cables_per_segment;
  if (!options.cable_angles_deg.empty()) return static_cast<int>(options.cable_angles_deg.size());
  return 4;
}

}  // namespace

int cables_per_segment(const GeometryOptions& options) { return cables_for(options, {}, 0); }

model::RobotGeometry<double> make_geometry(const GeometryOptions& options, int segment_count,
                                           const std::vector<int>& segment_cables) {
  require_positive(options.backbone_length_mm, "--length", "mm");
  require_positive(options.anchor_radius_mm, "--radius", "mm");
  require_positive(options.theta_max_rad, "--theta-max", "rad");
  // Beyond pi the cable lengths no longer determine theta (eq. 5 is an asin).
  if (options.theta_max_rad > kPi) {
    throw InputError(fmt::format("--theta-max must not exceed pi rad (got {} rad)", options.theta_max_rad));
  }
  constexpr int capacity = model::RobotGeometry<double>::kCapacity;
  if (segment_count < 1 || segment_count > capacity) {
    throw InputError(fmt::format("--segments must be between 1 and {} (got {})", capacity, segment_count));
  }
  auto geometry = model::RobotGeometry<double>::uniform(segment_count, options.backbone_length_mm,
                                                        options.anchor_radius_mm, options.theta_max_rad);
  for (int i = 0; i < segment_count; ++i) geometry.segments[i].cables = layout_for(options, cables_for(options, segment_cables, i));
  if (const model::Status status = geometry.validate(); status != model::Status::ok) {
    throw InputError(fmt::format("invalid geometry: {}", model::to_string(status)));
  }
  return geometry;
}

}  // namespace cdcr::cli
