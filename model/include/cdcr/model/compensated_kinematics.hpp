#pragma once
// The forward path that the firmware runs each cycle, and that the host tools
// run to measure it: cable lengths -> joints -> nominal pose -> GP error twist
// -> compensated pose (eqs. 5, 13, 16, 19); with an image's compliance block
// the nominal pose is the one sagged under the tip payload.

#include "cdcr/model/cable_fit.hpp"
#include "cdcr/model/chain.hpp"
#include "cdcr/model/compensation.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/gp_correction.hpp"
#include "cdcr/model/payload_compliance.hpp"
#include "cdcr/model/status.hpp"

namespace cdcr::model {

// The nominal geometry that an image was trained against.
template <typename S, int Max>
Status geometry_from_image(const ImageView& image, RobotGeometry<S, Max>& geometry) {
  if (image.segment_count < 1 || image.segment_count > Max) return Status::invalid_segment_count;
  RobotGeometry<S, Max> g;
  g.segment_count = image.segment_count;
  for (int i = 0; i < image.segment_count; ++i) {
    g.segments[i] = SegmentGeometry<S>{S(image.geometry[3 * i]), S(image.geometry[3 * i + 1]),
                                       S(image.geometry[3 * i + 2])};
    if (image.cables != nullptr) {
      // The angles as the image holds them (float), in S.
      const float* angles = image.cables + i * image_cables_field::per_segment + image_cables_field::angles;
      S psi[kMaxCablesPerSegment];
      for (int j = 0; j < kMaxCablesPerSegment; ++j) psi[j] = S(angles[j]);
      g.segments[i].cables = CableLayout<S>::at_angles(image_segment_cables(image, i), psi);
    }
  }
  if (const Status s = g.validate(); s != Status::ok) return s;
  geometry = g;
  return Status::ok;
}

template <typename S, int Max = kMaxSegments>
struct ForwardResult {
  JointVector<S, Max> joints;
  // The cables' residuals (cable_fit.hpp), for a correction that takes them;
  // empty otherwise.
  CableResiduals<S, Max> cable_residuals;
  Pose<S> nominal;
  Twist<S> error_twist = Twist<S>::Zero();
  Pose<S> compensated;
};

// Outputs are written only when the cables are valid. cable_resolution_mm as
// in joints_from_cables. nominal_shape(bend) gives the bends whose plain
// kinematics is the nominal pose: the bend itself, or (with a compliance
// model) the bends sagged under the payload. The GP correction stays
// evaluated at the commanded bends, as it was trained. A correction with the
// cable-fit encoding takes what the cables say beyond the bend, and takes
// every possible cable set (fit_measured_cables): it was trained on rows
// beyond the bend limit and the anchors' reach; its extrapolation flag says
// where it has not seen them. Otherwise the cables must be within the
// limits (joints_from_cables).
template <typename S, typename Accumulator, int Max, typename Arch, typename NominalShape>
Status compensated_forward_with(const CableVector<S, Max>& cables_mm, const RobotGeometry<S, Max>& geometry,
                                const GpCorrection<S, Accumulator, Max, Arch>& correction,
                                ForwardResult<S, Max>& result, S cable_resolution_mm, NominalShape&& nominal_shape) {
  JointVector<S, Max> joints;
  CableResiduals<S, Max> residuals;
  const Status s = correction.takes_cable_residuals()
                       ? fit_measured_cables(cables_mm, geometry, joints, residuals, cable_resolution_mm)
                       : joints_from_cables(cables_mm, geometry, joints, cable_resolution_mm);
  if (s != Status::ok) return s;
  const JointVector<S, Max> bend = bend_from_joints(joints);
  result.joints = joints;
  result.cable_residuals = residuals;
  result.nominal = forward_kinematics_bend(nominal_shape(bend), geometry);
  // One call for both kinds (empty residuals for a correction without
  // them): each call site of the GP's loops is its own code on a board.
  result.error_twist = correction.predict(bend, residuals);
  result.compensated = compensate(result.error_twist, result.nominal);
  return Status::ok;
}

template <typename S, typename Accumulator, int Max, typename Arch>
Status compensated_forward(const CableVector<S, Max>& cables_mm, const RobotGeometry<S, Max>& geometry,
                           const GpCorrection<S, Accumulator, Max, Arch>& correction, ForwardResult<S, Max>& result,
                           S cable_resolution_mm = S(0)) {
  return compensated_forward_with(cables_mm, geometry, correction, result, cable_resolution_mm,
                                  [](const JointVector<S, Max>& bend) -> const JointVector<S, Max>& { return bend; });
}

// The same with a compliance model (payload_compliance.hpp): the nominal
// pose sags under the correction's payload. An empty one changes nothing.
template <typename S, typename Accumulator, int Max, typename Arch>
Status compensated_forward(const CableVector<S, Max>& cables_mm, const RobotGeometry<S, Max>& geometry,
                           const GpCorrection<S, Accumulator, Max, Arch>& correction,
                           const PayloadCompliance<S, Max>& compliance, ForwardResult<S, Max>& result,
                           S cable_resolution_mm = S(0)) {
  return compensated_forward_with(cables_mm, geometry, correction, result, cable_resolution_mm,
                                  [&](const JointVector<S, Max>& bend) {
                                    return sagged_bends(bend, geometry, correction.payload_kg(), compliance);
                                  });
}

}  // namespace cdcr::model
