#pragma once
// What all of a segment's cables say, not only their two differences.
//
// joints_from_cables (segment.hpp) reads the bend from l3 - l1 and l2 - l4
// and ignores what the pairs' sums say. On a real robot they say a lot: a
// slack cable, or both cables of a pair pulled against the backbone, moves
// the tip while leaving the differences alone. The fit below keeps it.
//
// Eq. (2) with the backbone's length L' left free (an axially compressed
// backbone, cables slack in common) reads l_j = m - v . e_j with
//   m = L' s(theta),  v = r s(theta) b = 2 r sin(theta/2) (cos alpha, sin alpha),
// s(theta) = sin(theta/2)/(theta/2) and e_j = (cos psi_j, sin psi_j) the
// direction of cable j's anchor, psi_j = -(j - 1) 90 degrees (cables 1 to 4
// at 0, -90, -180 and -270 degrees, the order eq. (2) numbers them). (m, v)
// is a one-to-one change of (L', alpha, theta) for theta < pi, and the model
// is linear in (m, v): the least-squares fit of all four cables to eq. (2)
// is the linear one,
//   m = mean(l),  v = ((l3 - l1)/2, (l2 - l4)/2),
// so its bend is exactly today's (alpha = atan2(l2 - l4, l3 - l1), theta =
// 2 asin(|v| / 2r)). Other layouts (three cables at 120 degrees, measured
// angles) fit the same way with their own weights (geometry.hpp's
// CableLayout). What the fit leaves are the cable inputs the GP may take:
//   * the common mode, m - L s(theta): the cables' mean length against the
//     arc's (negative when the backbone is compressed or all cables slack);
//   * the pairs' imbalance, ((l1 + l3) - (l2 + l4)) / 2: one pair pulled
//     against the other, the one thing four cables say that the fit's three
//     parameters cannot (its residual is this value, +-1/2 per cable); with
//     measured angles, n . l (CableLayout::imbalance_weights). Three cables
//     leave nothing beyond (m, v): their imbalance is 0.
// Cables that are exactly consistent give zeros (to rounding).
//
// The fit refuses nothing but impossible lengths (non-finite or not
// positive). Differences beyond the reach of the anchors (|v| > 2r) bend the
// segment by pi, in the direction they point; such a row is far from
// consistent and says so. The bend limit theta_max is the runtime's, not
// the fit's: measured rows beyond it are data too.

#include <algorithm>
#include <array>
#include <cmath>

#include "cdcr/model/geometry.hpp"
#include "cdcr/model/segment.hpp"
#include "cdcr/model/series.hpp"
#include "cdcr/model/status.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model {

template <typename S>
struct SegmentCableFit {
  SegmentJoints<S> joints;
  S common_mode_mm = S(0);     // mean(l) - L s(theta)
  S pair_imbalance_mm = S(0);  // ((l1 + l3) - (l2 + l4)) / 2
  bool beyond_reach = false;   // |l3 - l1, l2 - l4| > 4 r: theta set to pi
};

// n . l, the pairs (1, 3) and (2, 4) summed first as eq. (2)'s pairs are.
template <typename S, typename Derived>
S pair_imbalance(const CableLayout<S>& layout, const Eigen::MatrixBase<Derived>& cables_mm) {
  if (layout.count != 4) return S(0);
  const std::array<S, kMaxCablesPerSegment>& n = layout.imbalance_weights;
  return (n[0] * cables_mm[0] + n[2] * cables_mm[2]) + (n[1] * cables_mm[1] + n[3] * cables_mm[3]);
}

// The two residuals of a segment's cables at a bending angle theta.
template <typename S, typename Derived>
Vec2<S> segment_cable_residuals(const Eigen::MatrixBase<Derived>& cables_mm, const SegmentGeometry<S>& geometry,
                                S theta_rad) {
  const CableLayout<S>& layout = geometry.cables;
  const S mean = layout_sum(layout.mean_weights, cables_mm, layout.count);
  return Vec2<S>(mean - geometry.backbone_length_mm * series::sinc(theta_rad / S(2)),
                 pair_imbalance(layout, cables_mm));
}

template <typename S, typename Derived>
Status fit_cables(const Eigen::MatrixBase<Derived>& cables_mm, const SegmentGeometry<S>& geometry,
                  SegmentCableFit<S>& fit) {
  // The differences joints_from_cables reads, so consistent cables give the
  // same bits.
  const CableDifferences<S> d = cable_differences(cables_mm, geometry);
  if (d.status != Status::ok) return d.status;
  SegmentCableFit<S> result;
  result.beyond_reach = d.chord > d.reach;
  const S theta = S(2) * std::asin(std::min(d.chord / d.reach, S(1)));
  result.joints = SegmentJoints<S>{std::atan2(d.d24, d.d31), theta};
  const Vec2<S> residuals = segment_cable_residuals(cables_mm, geometry, theta);
  result.common_mode_mm = residuals[0];
  result.pair_imbalance_mm = residuals[1];
  fit = result;
  return Status::ok;
}

// The cables that eq. (2) gives for a fit, its residuals included: the
// inverse of fit_cables for theta < pi (a check of both, and how a
// simulated robot's inconsistent cables are written down).
template <typename S>
SegmentCables<S> cables_from_fit(const SegmentCableFit<S>& fit, const SegmentGeometry<S>& geometry) {
  const Vec2<S> b = bend_from_joints(fit.joints);
  const S s = series::sinc(fit.joints.theta_rad / S(2));
  const S mean = geometry.backbone_length_mm * s + fit.common_mode_mm;
  const S r = geometry.anchor_radius_mm * s;
  const CableLayout<S>& layout = geometry.cables;
  SegmentCables<S> cables(layout.count);
  for (int j = 0; j < layout.count; ++j) {
    cables[j] = mean - r * (b.x() * layout.anchor_x[j] + b.y() * layout.anchor_y[j]) +
                fit.pair_imbalance_mm * layout.imbalance_weights[j];
  }
  return cables;
}

// A row is far from consistent with constant curvature when its fit leaves
// more than this in either residual, or its differences are beyond reach:
// a few times what a drive's encoder and a cable's stretch under a normal
// load account for.
inline constexpr double kFarFromConsistentMm = 0.5;

template <typename S>
bool far_from_consistent(S common_mode_mm, S pair_imbalance_mm) {
  return std::abs(common_mode_mm) > S(kFarFromConsistentMm) || std::abs(pair_imbalance_mm) > S(kFarFromConsistentMm);
}

template <typename S>
bool far_from_consistent(const SegmentCableFit<S>& fit) {
  return fit.beyond_reach || far_from_consistent(fit.common_mode_mm, fit.pair_imbalance_mm);
}

// Per segment, the fit's residuals stacked [common mode, pair imbalance, ...]
// like the bend pairs.
template <typename S, int MaxSegments = kMaxSegments>
using CableResiduals = JointVector<S, MaxSegments>;

// The residuals as the GP takes them (input_encoding.hpp): per segment the
// common mode, and with four cables (four_cables[i]) the pairs' imbalance;
// three cables leave none. `out` receives the returned count of values.
template <typename Derived, typename S>
int residual_inputs(const Eigen::MatrixBase<Derived>& residuals, int segments, const bool* four_cables, S* out) {
  int e = 0;
  for (int i = 0; i < segments; ++i) {
    out[e++] = residuals[2 * i];
    if (four_cables[i]) out[e++] = residuals[2 * i + 1];
  }
  return e;
}

template <typename S, int Max>
int residual_inputs(const CableResiduals<S, Max>& residuals, const RobotGeometry<S, Max>& geometry, S* out) {
  bool four_cables[Max] = {};
  for (int i = 0; i < geometry.segment_count; ++i) four_cables[i] = geometry.segments[i].cables.count == 4;
  return residual_inputs(residuals, geometry.segment_count, four_cables, out);
}

// Every segment's fit. Writes the outputs only on success.
template <typename S, int Max>
Status fit_cables(const CableVector<S, Max>& cables_mm, const RobotGeometry<S, Max>& geometry,
                  JointVector<S, Max>& joints, CableResiduals<S, Max>& residuals, int* far_segments = nullptr) {
  if (const Status s = geometry.validate(); s != Status::ok) return s;
  if (cables_mm.size() != geometry.cable_count()) return Status::invalid_segment_count;
  JointVector<S, Max> q(2 * geometry.segment_count);
  CableResiduals<S, Max> rho(2 * geometry.segment_count);
  int far = 0;
  for (int i = 0, first = 0; i < geometry.segment_count; first += geometry.segments[i].cables.count, ++i) {
    SegmentCableFit<S> fit;
    const auto segment_cables = cables_mm.segment(first, geometry.segments[i].cables.count);
    if (const Status s = fit_cables(segment_cables, geometry.segments[i], fit); s != Status::ok) return s;
    q[2 * i] = fit.joints.alpha_rad;
    q[2 * i + 1] = fit.joints.theta_rad;
    rho[2 * i] = fit.common_mode_mm;
    rho[2 * i + 1] = fit.pair_imbalance_mm;
    far += far_from_consistent(fit) ? 1 : 0;
  }
  joints = q;
  residuals = rho;
  if (far_segments != nullptr) *far_segments = far;
  return Status::ok;
}

// Only the residuals, for cables whose joints are already known to be valid
// (the runtime's forward path, after joints_from_cables).
template <typename S, int Max>
void cable_residuals(const CableVector<S, Max>& cables_mm, const RobotGeometry<S, Max>& geometry,
                     const JointVector<S, Max>& joints, CableResiduals<S, Max>& residuals) {
  residuals.resize(2 * geometry.segment_count);
  for (int i = 0, first = 0; i < geometry.segment_count; first += geometry.segments[i].cables.count, ++i) {
    residuals.template segment<2>(2 * i) = segment_cable_residuals(
        cables_mm.segment(first, geometry.segments[i].cables.count), geometry.segments[i], joints[2 * i + 1]);
  }
}

// The joints and residuals of measured cables as a model with the cable-fit
// encoding takes them, in training and on the board alike:
// joints_from_cables where it accepts the cables (a segment at its limit
// reads as the limit, as the runtime reads it), the fit's bend where it does
// not (beyond theta_max or the anchors' reach). Fails only for impossible
// lengths. beyond_limit (optional) tells which.
template <typename S, int Max>
Status fit_measured_cables(const CableVector<S, Max>& cables_mm, const RobotGeometry<S, Max>& geometry,
                           JointVector<S, Max>& joints, CableResiduals<S, Max>& residuals,
                           S cable_resolution_mm = S(0), bool* beyond_limit = nullptr, int* far_segments = nullptr) {
  JointVector<S, Max> q;
  CableResiduals<S, Max> rho;
  // The fit only where the runtime's map refuses: on the cycle's path the
  // common case costs the map and the residuals, no more.
  const bool within = joints_from_cables(cables_mm, geometry, q, cable_resolution_mm) == Status::ok;
  if (within) {
    cable_residuals(cables_mm, geometry, q, rho);
    if (far_segments != nullptr) {
      // Within reach: only the residuals can make a segment far.
      *far_segments = 0;
      for (int i = 0; i < geometry.segment_count; ++i) {
        *far_segments += far_from_consistent(rho[2 * i], rho[2 * i + 1]) ? 1 : 0;
      }
    }
  } else if (const Status s = fit_cables(cables_mm, geometry, q, rho, far_segments); s != Status::ok) {
    return s;
  }
  if (beyond_limit != nullptr) *beyond_limit = !within;
  joints = q;
  residuals = rho;
  return Status::ok;
}

}  // namespace cdcr::model
