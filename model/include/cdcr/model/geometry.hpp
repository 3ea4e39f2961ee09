#pragma once
// Geometry of the robot: segments are identical in the paper's prototype, but
// each segment carries its own parameters so calibrated or mixed robots fit.

#include <array>
#include <cmath>

#include "cdcr/model/limits.hpp"
#include "cdcr/model/status.hpp"

namespace cdcr::model {

// The cables of a segment: how many, where each is anchored on the anchor
// circle, and the least-squares read-out of eq. (2) for that layout.
//
// Cable j's anchor lies in the direction e_j = (cos psi_j, sin psi_j) of the
// segment's base frame. Eq. (2) with the cables' mean length m left free
// reads l_j = m - (D / 2) . e_j, where D = 4 r sin(theta/2) (cos alpha,
// sin alpha) is the chord vector. It is linear in (m, D), so the fit of all
// of a segment's cables is (m, D) = W l with W = (A^T A)^-1 A^T, A's rows
// (1, -e_j / 2). The paper's four cables at psi_j = -(j - 1) 90 degrees give
// m = mean(l), D = (l3 - l1, l2 - l4): eqs. (3)-(5). Three cables at 120
// degrees give m = mean(l), D = -(4/3) sum l_j e_j. What four cables say
// beyond (m, D) is one number, n . l, with n the unit vector orthogonal to
// A's columns (the pairs' imbalance, n = (1, -1, 1, -1) / 2, for the
// paper's); three say nothing more.
//
// The default is the paper's layout with exact weights, so that its values
// stay what eqs. (3)-(5) give, bit for bit.
template <typename S>
struct CableLayout {
  int count;
  std::array<S, kMaxCablesPerSegment> anchor_x;
  std::array<S, kMaxCablesPerSegment> anchor_y;
  // Rows of W, `count` weights each.
  std::array<S, kMaxCablesPerSegment> mean_weights;
  std::array<S, kMaxCablesPerSegment> chord_x_weights;
  std::array<S, kMaxCablesPerSegment> chord_y_weights;
  // n with four cables (its first entry positive); zeros with three.
  std::array<S, kMaxCablesPerSegment> imbalance_weights;

  // The paper's layout. Not inlined: every geometry holds one a segment,
  // and the boards' code would repeat the 24 values at each geometry made.
  [[gnu::noinline]] CableLayout()
      : count(4),
        anchor_x{S(1), S(0), S(-1), S(0)},
        anchor_y{S(0), S(-1), S(0), S(1)},
        mean_weights{S(0.25), S(0.25), S(0.25), S(0.25)},
        chord_x_weights{S(-1), S(0), S(1), S(0)},
        chord_y_weights{S(0), S(1), S(0), S(-1)},
        imbalance_weights{S(0.5), S(-0.5), S(0.5), S(-0.5)} {}

  // Anchors at psi_j = -(j - 1) 360 / count degrees, cable 1 on the x axis.
  static CableLayout evenly_spaced(int count) {
    if (count == 4) return CableLayout{};
    S psi[kMaxCablesPerSegment] = {};
    for (int j = 0; j < count && j < kMaxCablesPerSegment; ++j) {
      psi[j] = -S(j) * S(2 * 3.14159265358979323846) / S(count);
    }
    return at_angles(count, psi);
  }

  // Anchors at measured angles (rad). validate() says whether they read a
  // bend: at least three, not all on one line through the centre.
  static CableLayout at_angles(int count, const S* psi_rad) {
    CableLayout layout;
    layout.count = count;
    layout.anchor_x.fill(S(0));
    layout.anchor_y.fill(S(0));
    layout.imbalance_weights.fill(S(0));
    if (count < kMinCablesPerSegment || count > kMaxCablesPerSegment) return layout;
    for (int j = 0; j < count; ++j) {
      layout.anchor_x[j] = std::cos(psi_rad[j]);
      layout.anchor_y[j] = std::sin(psi_rad[j]);
    }
    layout.derive_weights();
    return layout;
  }

  Status validate() const {
    if (count < kMinCablesPerSegment || count > kMaxCablesPerSegment) return Status::invalid_geometry;
    for (int j = 0; j < count; ++j) {
      if (!std::isfinite(anchor_x[j]) || !std::isfinite(anchor_y[j]) || !std::isfinite(mean_weights[j]) ||
          !std::isfinite(chord_x_weights[j]) || !std::isfinite(chord_y_weights[j]) ||
          !std::isfinite(imbalance_weights[j])) {
        return Status::non_finite_input;
      }
      const S norm_sq = anchor_x[j] * anchor_x[j] + anchor_y[j] * anchor_y[j];
      if (!(std::abs(norm_sq - S(1)) < S(1e-3))) return Status::invalid_geometry;
    }
    return spread() > S(kLeastAnchorSpread) ? Status::ok : Status::invalid_geometry;
  }

  bool operator==(const CableLayout& other) const {
    return count == other.count && anchor_x == other.anchor_x && anchor_y == other.anchor_y &&
           mean_weights == other.mean_weights && chord_x_weights == other.chord_x_weights &&
           chord_y_weights == other.chord_y_weights && imbalance_weights == other.imbalance_weights;
  }
  bool operator!=(const CableLayout& other) const { return !(*this == other); }

  template <typename T>
  CableLayout<T> cast() const {
    CableLayout<T> layout;
    layout.count = count;
    for (int j = 0; j < kMaxCablesPerSegment; ++j) {
      layout.anchor_x[j] = T(anchor_x[j]);
      layout.anchor_y[j] = T(anchor_y[j]);
      layout.mean_weights[j] = T(mean_weights[j]);
      layout.chord_x_weights[j] = T(chord_x_weights[j]);
      layout.chord_y_weights[j] = T(chord_y_weights[j]);
      layout.imbalance_weights[j] = T(imbalance_weights[j]);
    }
    return layout;
  }

  // The smallest eigenvalue of the anchors' scatter about their mean, per
  // cable: 1/2 for evenly spaced anchors, 0 for anchors on one line.
  S spread() const {
    S mx = S(0), my = S(0);
    for (int j = 0; j < count; ++j) {
      mx += anchor_x[j];
      my += anchor_y[j];
    }
    mx /= S(count);
    my /= S(count);
    S sxx = S(0), sxy = S(0), syy = S(0);
    for (int j = 0; j < count; ++j) {
      sxx += (anchor_x[j] - mx) * (anchor_x[j] - mx);
      sxy += (anchor_x[j] - mx) * (anchor_y[j] - my);
      syy += (anchor_y[j] - my) * (anchor_y[j] - my);
    }
    const S half_trace = (sxx + syy) / S(2);
    const S root = std::sqrt(((sxx - syy) / S(2)) * ((sxx - syy) / S(2)) + sxy * sxy);
    return (half_trace - root) / S(count);
  }

  // Anchors closer to one line than this read the bend across it too
  // poorly (evenly spaced ones: 0.5).
  static constexpr double kLeastAnchorSpread = 0.05;

 private:
  // W = (A^T A)^-1 A^T and n from the anchors.
  void derive_weights() {
    S ata[3][3] = {};
    for (int j = 0; j < count; ++j) {
      const S row[3] = {S(1), -anchor_x[j] / S(2), -anchor_y[j] / S(2)};
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) ata[a][b] += row[a] * row[b];
      }
    }
    S inverse[3][3];
    if (!invert3(ata, inverse)) {
      // Anchors on one line: validate() refuses the layout.
      mean_weights.fill(S(0));
      chord_x_weights.fill(S(0));
      chord_y_weights.fill(S(0));
      return;
    }
    for (int j = 0; j < kMaxCablesPerSegment; ++j) {
      const bool used = j < count;
      const S row[3] = {S(1), -anchor_x[j] / S(2), -anchor_y[j] / S(2)};
      S w[3];
      for (int a = 0; a < 3; ++a) w[a] = inverse[a][0] * row[0] + inverse[a][1] * row[1] + inverse[a][2] * row[2];
      mean_weights[j] = used ? w[0] : S(0);
      chord_x_weights[j] = used ? w[1] : S(0);
      chord_y_weights[j] = used ? w[2] : S(0);
    }
    if (count == 4) {
      // n_j = (-1)^j det(A^T without column j), normalised.
      S n[4];
      S norm_sq = S(0);
      for (int j = 0; j < 4; ++j) {
        S m[3][3];
        for (int k = 0, c = 0; k < 4; ++k) {
          if (k == j) continue;
          m[0][c] = S(1);
          m[1][c] = -anchor_x[k] / S(2);
          m[2][c] = -anchor_y[k] / S(2);
          ++c;
        }
        n[j] = (j % 2 == 0 ? S(1) : S(-1)) * det3(m);
        norm_sq += n[j] * n[j];
      }
      const S scale = (n[0] < S(0) ? S(-1) : S(1)) / std::sqrt(norm_sq);
      for (int j = 0; j < 4; ++j) imbalance_weights[j] = n[j] * scale;
    }
  }

  static S det3(const S (&m)[3][3]) {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  }

  static bool invert3(const S (&m)[3][3], S (&out)[3][3]) {
    const S det = det3(m);
    if (!(std::abs(det) > S(1e-9))) return false;
    out[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) / det;
    out[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det;
    out[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det;
    out[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) / det;
    out[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det;
    out[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det;
    out[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) / det;
    out[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det;
    out[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det;
    return true;
  }
};

template <typename S>
struct SegmentGeometry {
  S backbone_length_mm;  // L: arc length of the flexible backbone
  S anchor_radius_mm;    // r: radius of the circle of cable anchor points
  S theta_max_rad;       // upper bound of the bending angle theta
  CableLayout<S> cables{};  // the paper's four cables at 90 degrees unless given

  Status validate() const {
    if (!std::isfinite(backbone_length_mm) || !std::isfinite(anchor_radius_mm) || !std::isfinite(theta_max_rad)) {
      return Status::non_finite_input;
    }
    if (!(backbone_length_mm > S(0)) || !(anchor_radius_mm > S(0)) || !(theta_max_rad > S(0))) {
      return Status::invalid_geometry;
    }
    // The layout's values are checked where it is made (CableLayout::
    // validate(), the image parser): this runs in every cycle.
    if (cables.count < kMinCablesPerSegment || cables.count > kMaxCablesPerSegment) return Status::invalid_geometry;
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
      g.segments[i] = {T(segments[i].backbone_length_mm), T(segments[i].anchor_radius_mm), T(segments[i].theta_max_rad),
                       segments[i].cables.template cast<T>()};
    }
    return g;
  }

  // The cables of the first segment_count segments, and where segment i's
  // first cable sits in a cable vector (segment by segment, in order).
  int cable_count() const { return first_cable(segment_count); }
  int first_cable(int segment) const {
    int first = 0;
    for (int i = 0; i < segment && i < MaxSegments; ++i) first += segments[i].cables.count;
    return first;
  }
  // Every segment has the paper's four cables at 90 degrees.
  bool paper_cables() const {
    for (int i = 0; i < segment_count; ++i) {
      if (segments[i].cables != CableLayout<S>{}) return false;
    }
    return true;
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
