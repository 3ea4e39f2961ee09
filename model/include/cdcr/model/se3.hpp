#pragma once
// Rigid-body transforms and the exponential coordinates of SE(3).
//
// Conventions, used by every file of the project:
//   * A twist is ordered (v, omega): linear part first, angular part second.
//   * hat(xi) = [[hat3(omega), v], [0, 0]], and exp(hat(xi)) is the pose.
//   * Lengths are millimetres, angles radians.

#include <algorithm>
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cdcr/model/series.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model {

template <typename S>
struct Pose {
  Mat3<S> rotation = Mat3<S>::Identity();
  Vec3<S> position_mm = Vec3<S>::Zero();

  static Pose identity() { return Pose{}; }

  static Pose from_matrix(const Mat4<S>& m) {
    return Pose{m.template topLeftCorner<3, 3>(), m.template topRightCorner<3, 1>()};
  }

  Mat4<S> matrix() const {
    Mat4<S> m = Mat4<S>::Identity();
    m.template topLeftCorner<3, 3>() = rotation;
    m.template topRightCorner<3, 1>() = position_mm;
    return m;
  }

  Pose operator*(const Pose& rhs) const {
    return Pose{rotation * rhs.rotation, rotation * rhs.position_mm + position_mm};
  }

  Pose inverse() const {
    const Mat3<S> rt = rotation.transpose();
    return Pose{rt, -(rt * position_mm)};
  }

  template <typename T>
  Pose<T> cast() const {
    return Pose<T>{rotation.template cast<T>(), position_mm.template cast<T>()};
  }

  bool all_finite() const { return rotation.allFinite() && position_mm.allFinite(); }
};

template <typename S>
Mat3<S> hat3(const Vec3<S>& w) {
  Mat3<S> m;
  m << S(0), -w.z(), w.y(),
       w.z(), S(0), -w.x(),
      -w.y(), w.x(), S(0);
  return m;
}

template <typename S>
Vec3<S> vee3(const Mat3<S>& m) {
  return Vec3<S>(m(2, 1), m(0, 2), m(1, 0));
}

template <typename S>
Mat4<S> hat(const Twist<S>& xi) {
  Mat4<S> m = Mat4<S>::Zero();
  m.template topLeftCorner<3, 3>() = hat3<S>(xi.template tail<3>());
  m.template topRightCorner<3, 1>() = xi.template head<3>();
  return m;
}

template <typename S>
Twist<S> vee(const Mat4<S>& m) {
  Twist<S> xi;
  xi.template head<3>() = m.template topRightCorner<3, 1>();
  xi.template tail<3>() = vee3<S>(m.template topLeftCorner<3, 3>());
  return xi;
}

// Rotation by the vector w (axis times angle): Rodrigues' formula.
template <typename S>
Mat3<S> exp_so3(const Vec3<S>& w) {
  const S angle = w.norm();
  const Mat3<S> W = hat3<S>(w);
  return Mat3<S>::Identity() + series::sinc(angle) * W + series::one_minus_cos_over_sq(angle) * (W * W);
}

template <typename S>
Pose<S> exp(const Twist<S>& xi) {
  const Vec3<S> w = xi.template tail<3>();
  const Vec3<S> v = xi.template head<3>();
  const S angle = w.norm();
  const Mat3<S> W = hat3<S>(w);
  const Mat3<S> W2 = W * W;
  const S a = series::sinc(angle);
  const S b = series::one_minus_cos_over_sq(angle);
  const S c = series::x_minus_sin_over_cube(angle);
  Pose<S> pose;
  pose.rotation = Mat3<S>::Identity() + a * W + b * W2;
  pose.position_mm = v + b * (W * v) + c * (W2 * v);
  return pose;
}

// Rotation vector of R, with angle in [0, pi]. The angle comes from atan2 of
// the skew and symmetric parts, which keeps full precision at both ends where
// acos loses it. Near pi the axis is read from the symmetric part instead,
// since the skew part vanishes there.
template <typename S>
Vec3<S> log_so3(const Mat3<S>& R) {
  const Vec3<S> skew = S(0.5) * vee3<S>(Mat3<S>(R - R.transpose()));  // sin(angle) * axis
  const S cos_angle = std::clamp(S(0.5) * (R.trace() - S(1)), S(-1), S(1));
  const S angle = std::atan2(skew.norm(), cos_angle);
  if (cos_angle > S(-0.7)) {
    return skew / series::sinc(angle);
  }
  // R + R^T = 2 cos(angle) I + 2 (1 - cos(angle)) axis axis^T.
  const Mat3<S> outer = (S(0.5) * (R + R.transpose()) - cos_angle * Mat3<S>::Identity()) / (S(1) - cos_angle);
  int k = 0;
  outer.diagonal().maxCoeff(&k);
  Vec3<S> axis = outer.col(k) / std::sqrt(outer(k, k));
  axis.normalize();
  if (axis.dot(skew) < S(0)) axis = -axis;
  return angle * axis;
}

template <typename S>
Twist<S> log(const Pose<S>& pose) {
  const Vec3<S> w = log_so3<S>(pose.rotation);
  const S angle = w.norm();
  const Mat3<S> W = hat3<S>(w);
  const Mat3<S> v_inverse =
      Mat3<S>::Identity() - S(0.5) * W + series::log_translation_coefficient(angle) * (W * W);
  Twist<S> xi;
  xi.template head<3>() = v_inverse * pose.position_mm;
  xi.template tail<3>() = w;
  return xi;
}

// Ad_T maps twists in the frame of T to the reference frame:
// hat(Ad_T xi) = T hat(xi) T^-1. In (v, omega) order: [[R, hat3(p) R], [0, R]].
template <typename S>
Mat6<S> adjoint(const Pose<S>& pose) {
  Mat6<S> ad = Mat6<S>::Zero();
  ad.template topLeftCorner<3, 3>() = pose.rotation;
  ad.template bottomRightCorner<3, 3>() = pose.rotation;
  ad.template topRightCorner<3, 3>() = hat3<S>(pose.position_mm) * pose.rotation;
  return ad;
}

// Ad_T applied to the columns of a 6xN block without forming the 6x6 matrix.
template <typename S, typename Derived>
void apply_adjoint(const Pose<S>& pose, Eigen::MatrixBase<Derived>& twists) {
  for (Eigen::Index j = 0; j < twists.cols(); ++j) {
    const Vec3<S> w = pose.rotation * twists.col(j).template tail<3>();
    const Vec3<S> v = pose.rotation * twists.col(j).template head<3>() + pose.position_mm.cross(w);
    twists.col(j).template head<3>() = v;
    twists.col(j).template tail<3>() = w;
  }
}

// The Lie bracket matrix: ad_xi eta = [xi, eta]. In (v, omega) order:
// [[hat3(omega), hat3(v)], [0, hat3(omega)]].
template <typename S>
Mat6<S> ad(const Twist<S>& xi) {
  Mat6<S> m = Mat6<S>::Zero();
  const Mat3<S> W = hat3<S>(xi.template tail<3>());
  m.template topLeftCorner<3, 3>() = W;
  m.template bottomRightCorner<3, 3>() = W;
  m.template topRightCorner<3, 3>() = hat3<S>(xi.template head<3>());
  return m;
}

// Left Jacobian of SE(3): d/dt exp(xi(t)) * exp(-xi(t)) = hat(J_l(xi) xi'(t)).
// Evaluated as the series sum_k ad_xi^k / (k+1)!, truncated after ten terms.
// It is meant for the small error twists of the compensation model (rotation
// well below 1 rad, where the truncation is below 1e-9 relative); it only
// steers inverse-kinematics steps, never the reported residual.
template <typename S>
Mat6<S> left_jacobian(const Twist<S>& xi) {
  const Mat6<S> a = ad<S>(xi);
  Mat6<S> sum = Mat6<S>::Identity();
  for (int k = 10; k >= 1; --k) {
    sum = Mat6<S>::Identity() + (a * sum) / S(k + 1);
  }
  return sum;
}

}  // namespace cdcr::model
