#pragma once
// Comparing a pose the board computed with the host's double result, and
// feeding a golden case to the runtime the way the bus would.

#include <cmath>
#include <cstdint>

#include <cdcr/firmware/protocol.hpp>
#include <cdcr/model/se3.hpp>

#include "board.hpp"
#include "qemu_golden.hpp"

namespace cdcr::boards::mps2 {

struct PoseDeviation {
  double position_mm = 0;
  double orientation_deg = 0;
};

// The angle of R_expected^T R from atan2(|skew part|, (trace - 1) / 2): acos
// of the trace alone would read float rounding in R (not quite orthonormal)
// as hundredths of a degree.
inline PoseDeviation deviation(const model::Pose<float>& pose, const double (&expected_position_mm)[3],
                               const double (&expected_rotation)[9]) {
  constexpr double kDegPerRad = 57.295779513082320876;
  PoseDeviation d;
  double sq = 0;
  for (int i = 0; i < 3; ++i) {
    const double e = static_cast<double>(pose.position_mm[i]) - expected_position_mm[i];
    sq += e * e;
  }
  d.position_mm = std::sqrt(sq);
  double m[3][3];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      m[i][j] = 0;
      for (int k = 0; k < 3; ++k) m[i][j] += expected_rotation[3 * k + i] * static_cast<double>(pose.rotation(k, j));
    }
  }
  const double wx = 0.5 * (m[2][1] - m[1][2]);
  const double wy = 0.5 * (m[0][2] - m[2][0]);
  const double wz = 0.5 * (m[1][0] - m[0][1]);
  const double cos_angle = 0.5 * (m[0][0] + m[1][1] + m[2][2] - 1.0);
  d.orientation_deg = std::atan2(std::sqrt(wx * wx + wy * wy + wz * wz), cos_angle) * kDegPerRad;
  return d;
}

// One cable feedback frame per segment, as the drives send them.
template <typename Can>
void deliver_cables(Can& can, int golden_case) {
  for (int s = 0; s < qemu_golden::kSegments; ++s) {
    hal::CanFrame frame = firmware::protocol::make_frame(firmware::protocol::kCableFeedbackBaseId + std::uint32_t(s), 8);
    for (int k = 0; k < 4; ++k) {
      firmware::protocol::put_raw(frame, firmware::protocol::signal::cable[k],
                                  qemu_golden::kCablesRaw[golden_case][4 * s + k]);
    }
    can.deliver(frame);
  }
}

inline firmware::Geometry golden_geometry() {
  firmware::Geometry geometry;
  geometry.segment_count = qemu_golden::kSegments;
  for (int s = 0; s < qemu_golden::kSegments; ++s) {
    geometry.segments[s] = {qemu_golden::kGeometry[s][0], qemu_golden::kGeometry[s][1], qemu_golden::kGeometry[s][2]};
  }
  return geometry;
}

}  // namespace cdcr::boards::mps2
