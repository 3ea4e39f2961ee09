#pragma once
// The segments' compliance under the tip load: how far each segment bends
// further under the weight at the tip. The trainer identifies it
// (tools/train/compliance_identification.hpp), the image carries it (flash
// image v2.3's compliance block), and the board's nominal model computes it
// every cycle; all three run the functions below.
//
// Each segment bends further by the moment of the tip load's weight about
// its base, times the segment's compliance:
//   b_i' = b_i + c_i (1 + s |b_i|) (m_y, -m_x),
//   m = R_i^T (m_tip (p_tip - p_i) x g),   m_tip = payload + m_0,
// in the segment's base frame R_i, p_i of the sagged shape. g c_0 is the
// weight of one kilogram times segment 0's compliance (rad per kg mm), in the
// base frame; c_i / c_0 a ratio per segment; s a softening with the
// segment's own (commanded) bend; m_0 an unloaded tip mass standing for the
// end platform's and the segments' own weight.
//
// The sag moves its own lever arms, so b' is a fixed point, found by
// iteration from the commanded shape. The inverse needs none: given the
// sagged shape, the moments are known, and b follows from b' with a scalar
// quadratic for |b| (commanded_bends).
//
// Templated on the scalar, header-only, allocation-free, without exceptions.

#include <array>
#include <cmath>
#include <utility>

#include "cdcr/model/chain.hpp"
#include "cdcr/model/geometry.hpp"
#include "cdcr/model/limits.hpp"
#include "cdcr/model/segment.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model {

// Newton steps of the sag's fixed point. The sag is not small: a kilogram
// bends the straight 480 mm prototype's tip by tens of millimetres (75 mm on
// the simulator), and the plain fixed-point iteration (moments on the shape
// the last pass left) gains only a factor of 2 to 4 a pass near the bending
// limit (8 passes still leave 1e-6 rad and 0.7 um at the tip with the
// simulator's compliance, 5e-4 rad and 0.4 mm with twice it). Newton's
// method with the analytic derivative of the moments (one chain pass with
// the segments' twists and an 8 x 8 solve a step) converges quadratically:
// with 1 kg plus the platform, over the workspace to every segment's
// bending limit, the largest bend error left after 1, 2 and 3 steps is
// 4e-3, 6e-6 and 1e-11 rad (tip 3.7 mm, 5 um, 1e-8 mm) with the simulator's
// compliance, and 4e-2, 7e-4 and 3e-7 rad (tip 30 mm, 0.6 mm, 0.25 um) with
// twice it (host_tests/model/payload_compliance_test.cpp prints them).
// Three steps are below float32's rounding of a bend of a radian (6e-8) for
// a robot as compliant as the ones measured, and within a fortieth of the
// image's fidelity target (0.01 mm) for one twice as compliant; a fourth
// costs a pass more for nothing the board can represent.
inline constexpr int kSagNewtonSteps = 3;

template <typename S, int MaxSegments>
using SagJacobian = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 2 * MaxSegments, 2 * MaxSegments>;

template <typename S, int MaxSegments = kMaxSegments>
struct PayloadCompliance {
  int segments = 0;  // the robot's segment count; 0: no compliance model
  // g c_0 (rad per kg mm of lever arm), in the base frame.
  Vec3<S> weighted_gravity = Vec3<S>::Zero();
  std::array<S, MaxSegments> ratio = filled(S(1));  // c_i / c_0
  S softening_per_rad = S(0);
  S unloaded_mass_kg = S(0);

  bool empty() const { return segments == 0 || (weighted_gravity.array() == S(0)).all(); }

  template <typename T>
  PayloadCompliance<T, MaxSegments> cast() const {
    PayloadCompliance<T, MaxSegments> c;
    c.segments = segments;
    c.weighted_gravity = weighted_gravity.template cast<T>();
    for (int i = 0; i < MaxSegments; ++i) c.ratio[i] = T(ratio[i]);
    c.softening_per_rad = T(softening_per_rad);
    c.unloaded_mass_kg = T(unloaded_mass_kg);
    return c;
  }

 private:
  static std::array<S, MaxSegments> filled(S value) {
    std::array<S, MaxSegments> a{};
    a.fill(value);
    return a;
  }
};

// What the image parser and the trainer's ranking require of a compliance
// model: ratios above zero, an unloaded mass not below zero, and a
// softening that keeps 1 + s |b| positive within a quarter turn.
template <typename S>
bool plausible_softening(S softening_per_rad) {
  return softening_per_rad > S(-1.0 / kComplianceLargestBendRad);
}

// The sag of every segment on the shape `shape` (a bend vector): the
// rotation vector c_i (m_y, -m_x) of each segment, without its softening,
// into `sag`. The moments are those of the load at the tip of `shape`.
// With `d_sag_d_shape`, also its derivative by the shape (2n x 2n): a change
// of segment j's bend moves every frame after it by the spatial twist
// (v, w) of tip_jacobian_bend, so the tip's lever arm about a base at or
// before it changes by v + w x p_tip, and a base after it turns with the
// tip (the moment turns by w x m in the base frame, the lever arm by
// w x (p_tip - p_i)).
template <typename S, int Max>
void sag_on_shape(const JointVector<S, Max>& shape, const RobotGeometry<S, Max>& geometry, S tip_mass_kg,
                  const PayloadCompliance<S, Max>& compliance, JointVector<S, Max>& sag,
                  SagJacobian<S, Max>* d_sag_d_shape = nullptr) {
  const int n = geometry.segment_count;
  Pose<S> bases[Max];
  Eigen::Matrix<S, 6, 2> twists[Max];
  Pose<S> frame;
  for (int i = 0; i < n; ++i) {
    bases[i] = frame;
    const Vec2<S> b = shape.template segment<2>(2 * i);
    const S length = geometry.segments[i].backbone_length_mm;
    if (d_sag_d_shape != nullptr) {
      twists[i] = segment_bend_twists<S>(b, length);
      apply_adjoint(frame, twists[i]);
    }
    frame = frame * segment_pose<S>(b, length);
  }
  const Vec3<S> weight = tip_mass_kg * compliance.weighted_gravity;
  const auto to_bend = [](const Vec3<S>& local) { return Vec2<S>(local.y(), -local.x()); };
  sag.resize(2 * n);
  if (d_sag_d_shape != nullptr) d_sag_d_shape->setZero(2 * n, 2 * n);
  for (int i = 0; i < n; ++i) {
    const Mat3<S> to_local = bases[i].rotation.transpose();
    const Vec3<S> arm = frame.position_mm - bases[i].position_mm;
    const Vec3<S> moment = arm.cross(weight);
    // A rotation vector (kx, ky, 0) is the bend (u, w) = (ky, -kx).
    sag.template segment<2>(2 * i) = compliance.ratio[i] * to_bend(to_local * moment);
    if (d_sag_d_shape == nullptr) continue;
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < 2; ++k) {
        const Vec3<S> v = twists[j].template block<3, 1>(0, k);
        const Vec3<S> w = twists[j].template block<3, 1>(3, k);
        const Vec3<S> change = j < i ? Vec3<S>(w.cross(arm).cross(weight) - w.cross(moment))
                                     : Vec3<S>((v + w.cross(frame.position_mm)).cross(weight));
        d_sag_d_shape->template block<2, 1>(2 * i, 2 * j + k) = compliance.ratio[i] * to_bend(to_local * change);
      }
    }
  }
}

// Solves a x = b for x, in place in b, by Gaussian elimination with partial
// pivoting. Eigen's LU is blocked for matrices of run-time size and takes
// its workspace from the heap; the system here is at most 2 kMaxSegments
// wide and close to the identity (I less the sag's derivative).
template <typename Matrix, typename Vector>
void solve_in_place(Matrix& a, Vector& b) {
  using S = typename Vector::Scalar;
  const int n = static_cast<int>(b.size());
  for (int k = 0; k < n; ++k) {
    int pivot = k;
    for (int i = k + 1; i < n; ++i) {
      if (std::abs(a(i, k)) > std::abs(a(pivot, k))) pivot = i;
    }
    if (pivot != k) {
      for (int j = 0; j < n; ++j) std::swap(a(k, j), a(pivot, j));
      std::swap(b[k], b[pivot]);
    }
    if (a(k, k) == S(0)) continue;
    for (int i = k + 1; i < n; ++i) {
      const S factor = a(i, k) / a(k, k);
      for (int j = k + 1; j < n; ++j) a(i, j) -= factor * a(k, j);
      b[i] -= factor * b[k];
    }
  }
  for (int k = n - 1; k >= 0; --k) {
    S sum = b[k];
    for (int j = k + 1; j < n; ++j) sum -= a(k, j) * b[j];
    b[k] = a(k, k) != S(0) ? sum / a(k, k) : S(0);
  }
}

// The bends with the sag of a tip load of payload_kg (plus the model's
// unloaded mass); the bends themselves for an empty model or no load.
// `newton_steps` of Newton's method on x - b - diag(1 + s |b_i|) sag(x) = 0
// from the commanded shape (sagged_bends: kSagNewtonSteps).
template <typename S, int Max>
JointVector<S, Max> sagged_bends_after(int newton_steps, const JointVector<S, Max>& bends,
                                       const RobotGeometry<S, Max>& geometry, S payload_kg,
                                       const PayloadCompliance<S, Max>& compliance) {
  const S tip_mass_kg = payload_kg + compliance.unloaded_mass_kg;
  if (compliance.empty() || tip_mass_kg == S(0)) return bends;
  const int n = geometry.segment_count;
  S softening[Max];
  for (int i = 0; i < n; ++i) {
    softening[i] = S(1) + compliance.softening_per_rad * bends.template segment<2>(2 * i).norm();
  }
  JointVector<S, Max> current = bends;
  JointVector<S, Max> sag;
  SagJacobian<S, Max> jacobian;
  for (int step = 0; step < newton_steps; ++step) {
    sag_on_shape(current, geometry, tip_mass_kg, compliance, sag, &jacobian);
    JointVector<S, Max> residual(2 * n);
    for (int i = 0; i < n; ++i) {
      residual.template segment<2>(2 * i) =
          current.template segment<2>(2 * i) - bends.template segment<2>(2 * i) - softening[i] * sag.template segment<2>(2 * i);
      jacobian.template middleRows<2>(2 * i) *= -softening[i];
    }
    jacobian.diagonal().array() += S(1);
    solve_in_place(jacobian, residual);
    current -= residual;
  }
  return current;
}

template <typename S, int Max>
JointVector<S, Max> sagged_bends(const JointVector<S, Max>& bends, const RobotGeometry<S, Max>& geometry,
                                 S payload_kg, const PayloadCompliance<S, Max>& compliance) {
  return sagged_bends_after(kSagNewtonSteps, bends, geometry, payload_kg, compliance);
}

// The nominal tip pose of the bends with that sag.
template <typename S, int Max>
Pose<S> sagged_pose(const JointVector<S, Max>& bends, const RobotGeometry<S, Max>& geometry, S payload_kg,
                    const PayloadCompliance<S, Max>& compliance) {
  return forward_kinematics_bend(sagged_bends(bends, geometry, payload_kg, compliance), geometry);
}

// The commanded bends b whose sag is the shape `sagged`: per segment, with
// k = c_i (m_y, -m_x) on that shape and a = b' - k, b = a - s |b| k, where
// |b| = t solves t^2 (1 - s^2 |k|^2) + 2 s (a.k) t - |a|^2 = 0 (the root at
// or above zero; s |k| is far below 1 for any plausible model). Exact for
// the converged fixed point; against sagged_bends' kSagNewtonSteps it is off
// by what those leave.
template <typename S, int Max>
JointVector<S, Max> commanded_bends(const JointVector<S, Max>& sagged, const RobotGeometry<S, Max>& geometry,
                                    S payload_kg, const PayloadCompliance<S, Max>& compliance) {
  const S tip_mass_kg = payload_kg + compliance.unloaded_mass_kg;
  if (compliance.empty() || tip_mass_kg == S(0)) return sagged;
  JointVector<S, Max> sag;
  sag_on_shape(sagged, geometry, tip_mass_kg, compliance, sag);
  JointVector<S, Max> bends(sagged.size());
  const S s = compliance.softening_per_rad;
  for (int i = 0; i < geometry.segment_count; ++i) {
    const Vec2<S> k = sag.template segment<2>(2 * i);
    const Vec2<S> a = sagged.template segment<2>(2 * i) - k;
    const S a_dot_k = a.dot(k);
    const S a_squared = a.squaredNorm();
    const S leading = S(1) - s * s * k.squaredNorm();
    // t = |a|^2 / (s a.k + sqrt((s a.k)^2 + leading |a|^2)): the positive
    // root without the cancellation of the textbook form.
    const S root = std::sqrt(s * a_dot_k * s * a_dot_k + leading * a_squared);
    const S denominator = s * a_dot_k + root;
    const S t = denominator > S(0) ? a_squared / denominator : S(0);
    bends.template segment<2>(2 * i) = a - s * t * k;
  }
  return bends;
}

}  // namespace cdcr::model
