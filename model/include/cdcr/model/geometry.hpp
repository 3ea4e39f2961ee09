#pragma once
// Geometry of the robot: segments are identical in the paper's prototype, but
// each segment carries its own parameters so calibrated or mixed robots fit.

#include <array>
#include <cmath>

#include "cdcr/model/limits.hpp"
#include "cdcr/model/status.hpp"

namespace cdcr::model {

template <typename S>
struct SegmentGeometry {
  S backbone_length_mm;  // L: arc length of the flexible backbone
  S anchor_radius_mm;    // r: radius of the circle of cable anchor points
  S theta_max_rad;       // upper bound of the bending angle theta

  Status validate() const {
    if (!std::isfinite(backbone_length_mm) || !std::isfinite(anchor_radius_mm) || !std::isfinite(theta_max_rad)) {
      return Status::non_finite_input;
    }
    if (!(backbone_length_mm > S(0)) || !(anchor_radius_mm > S(0)) || !(theta_max_rad > S(0))) {
      return Status::invalid_geometry;
    }
    return Status::ok;
  }
};

// The paper's prototype (Section V): four segments, L = 120 mm, r = 67 mm,
// theta in [0, pi/2]. Table 1 uses r = 70 mm instead.
inline constexpr int kPrototypeSegmentCount = 4;
inline constexpr double kPrototypeBackboneLengthMm = 120.0;
inline constexpr double kPrototypeAnchorRadiusMm = 67.0;
inline constexpr double kPrototypeThetaMaxRad = 1.5707963267948966;

template <typename S, int MaxSegments = kMaxSegments>
struct RobotGeometry {
  static constexpr int kCapacity = MaxSegments;

  int segment_count = 0;
  std::array<SegmentGeometry<S>, MaxSegments> segments{};

  static RobotGeometry uniform(int count, S backbone_length_mm, S anchor_radius_mm,
                               S theta_max_rad = S(kPrototypeThetaMaxRad)) {
    RobotGeometry g;
    g.segment_count = count;
    for (auto& s : g.segments) s = SegmentGeometry<S>{backbone_length_mm, anchor_radius_mm, theta_max_rad};
    return g;
  }

  static RobotGeometry prototype() {
    return uniform(kPrototypeSegmentCount, S(kPrototypeBackboneLengthMm), S(kPrototypeAnchorRadiusMm));
  }

  // The same geometry in another scalar type (a host's double model of the
  // firmware's float one).
  template <typename T>
  RobotGeometry<T, MaxSegments> cast() const {
    RobotGeometry<T, MaxSegments> g;
    g.segment_count = segment_count;
    for (int i = 0; i < MaxSegments; ++i) {
      g.segments[i] = {T(segments[i].backbone_length_mm), T(segments[i].anchor_radius_mm), T(segments[i].theta_max_rad)};
    }
    return g;
  }

  Status validate() const {
    if (segment_count < 1 || segment_count > MaxSegments) return Status::invalid_segment_count;
    for (int i = 0; i < segment_count; ++i) {
      if (const Status s = segments[i].validate(); s != Status::ok) return s;
    }
    return Status::ok;
  }
};

}  // namespace cdcr::model
