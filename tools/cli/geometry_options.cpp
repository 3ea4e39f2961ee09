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
}

model::RobotGeometry<double> make_geometry(const GeometryOptions& options, int segment_count) {
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
  const auto geometry = model::RobotGeometry<double>::uniform(segment_count, options.backbone_length_mm,
                                                              options.anchor_radius_mm, options.theta_max_rad);
  if (const model::Status status = geometry.validate(); status != model::Status::ok) {
    throw InputError(fmt::format("invalid geometry: {}", model::to_string(status)));
  }
  return geometry;
}

}  // namespace cdcr::cli
