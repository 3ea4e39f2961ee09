#pragma once
// Comparing a pose the board computed with the host's double result, and
// feeding a golden case to the runtime the way the bus would.

#include <cstdint>

#include <cdcr/firmware/protocol.hpp>
#include <cdcr/model/compensation.hpp>
#include <cdcr/model/units.hpp>

#include "board.hpp"
#include "qemu_golden.hpp"

namespace cdcr::boards::mps2 {

// A pose of the golden header: position in mm, rotation row-major.
template <typename S>
model::Pose<S> golden_pose(const double (&position_mm)[3], const double (&rotation)[9]) {
  model::Pose<S> pose;
  for (int i = 0; i < 3; ++i) pose.position_mm[i] = static_cast<S>(position_mm[i]);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) pose.rotation(r, c) = static_cast<S>(rotation[3 * r + c]);
  }
  return pose;
}

struct PoseDeviation {
  double position_mm = 0;
  double orientation_deg = 0;
};

// The board's float pose against the host's double one, measured in double
// (eq. 20, as the accuracy figures are).
inline PoseDeviation deviation(const model::Pose<float>& pose, const model::Pose<double>& expected) {
  model::Pose<double> widened;
  widened.position_mm = pose.position_mm.cast<double>();
  widened.rotation = pose.rotation.cast<double>();
  const model::PoseError<double> error = model::pose_error(widened, expected);
  return {error.position_mm, error.orientation_rad * model::kDegreesPerRadian};
}

// One cable feedback frame per segment, as the drives send them.
template <typename Can>
void deliver_cables(Can& can, int golden_case) {
  const double* lengths_mm = qemu_golden::kCablesMm[golden_case];
  for (int s = 0; s < qemu_golden::kSegments; ++s) {
    const firmware::protocol::CableFeedback feedback{
        s, {lengths_mm[4 * s], lengths_mm[4 * s + 1], lengths_mm[4 * s + 2], lengths_mm[4 * s + 3]}};
    hal::CanFrame frame;
    if (firmware::protocol::encode(feedback, frame)) can.deliver(frame);
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
