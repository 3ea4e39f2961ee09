#pragma once
// The board's compensated forward path, for any way of summing the GP: the
// runtime runs it with its own board's sums (estimate_pose, kinematics.cpp),
// and the trainer and `cdcr eval` run it on the host with each board's
// (tools/train/evaluation.cpp), so that what they report is what a board
// computes.

#include "cdcr/firmware/kinematics.hpp"
#include "cdcr/firmware/protocol/messages.hpp"

namespace cdcr::firmware {

// The drives report cable lengths in the protocol's steps: a segment at its
// bending limit may read one step beyond it.
inline constexpr Scalar kCableResolutionMm = Scalar(protocol::kLengthScaleMm);

// The compensated pose of the cables, with the kernel coordinates its
// variance starts from; the nominal pose sags under the correction's payload
// with a compliance block (sagged_bends_of, out of line). Writes `estimate`
// only on success.
template <typename GpCorrection>
model::Status estimate_compensated_pose(const Geometry& geometry, const GpCorrection& correction,
                                        const Uncertainty& uncertainty, const Compliance& compliance,
                                        const Cables& cables_mm, PoseEstimate& estimate) {
  model::ForwardResult<Scalar, kMaxSegments> result;
  const auto nominal_shape = [&](const Joints& bend) {
    return compliance.empty() ? bend : sagged_bends_of(compliance, geometry, correction.payload_kg(), bend);
  };
  if (const model::Status s = model::compensated_forward_with(cables_mm, geometry, correction, result,
                                                               kCableResolutionMm, nominal_shape);
      s != model::Status::ok) {
    return s;
  }
  estimate.pose = result.compensated;
  estimate.joints = result.joints;
  estimate.cable_residuals = result.cable_residuals;
  estimate.compensated = true;
  correction.kernel_coordinates(model::bend_from_joints(result.joints), result.cable_residuals,
                                estimate.kernel_coordinates);
  estimate.outside_range = uncertainty.outside_range(estimate.kernel_coordinates);
  return model::Status::ok;
}

}  // namespace cdcr::firmware
