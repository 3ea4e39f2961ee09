#pragma once
// The fixed imperfections of one physical robot, drawn once from the seed.
// Every value is drawn whether or not its source is enabled (and then zeroed
// if it is not), so switching one source off never changes another's values.

#include <array>
#include <cstdint>

#include <cdcr/model/geometry.hpp>
#include <cdcr/model/se3.hpp>

#include "sim/simulator_config.hpp"

namespace cdcr::sim {

struct SegmentDeviation {
  double backbone_length_error_mm = 0.0;
  double anchor_radius_error_mm = 0.0;
  double anchor_angle_offset_rad = 0.0;
  double curvature_gradient = 0.0;  // c of kappa(s) = kappa_mean (1 + c (2 s / L - 1))
};

struct RobotDeviations {
  static constexpr int kCapacity = model::kMaxSegments;

  std::array<SegmentDeviation, kCapacity> segments{};
  // segment_mounts[i] sits between the end disk of segment i and the base of
  // segment i + 1 (i < n - 1).
  std::array<model::Pose<double>, kCapacity> segment_mounts{};
  model::Pose<double> base_mount;      // robot base in the measurement's base frame
  model::Pose<double> platform_mount;  // marker frame in the last end disk's frame
};

RobotDeviations draw_deviations(int segment_count, const SimulatorConfig& config);

}  // namespace cdcr::sim
