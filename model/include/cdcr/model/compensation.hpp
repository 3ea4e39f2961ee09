#pragma once
// Tip error and its compensation (Section IV-B).

#include "cdcr/model/se3.hpp"
#include "cdcr/model/types.hpp"

namespace cdcr::model {

// Eq. (18): eps = log(T_measured T_nominal^-1)^vee, a twist in the base frame,
// ordered (v, omega). This is what the GP learns.
template <typename S>
Twist<S> tip_error_twist(const Pose<S>& measured, const Pose<S>& nominal) {
  return log(measured * nominal.inverse());
}

// Eq. (19): T_c = exp(eps) T_nominal.
template <typename S>
Pose<S> compensate(const Twist<S>& error_twist, const Pose<S>& nominal) {
  return exp(error_twist) * nominal;
}

// Position error |p_a - p| in mm and orientation error, the rotation angle of
// R_a R^T in rad (eq. 20 as reported in Tables 2-3).
template <typename S>
struct PoseError {
  S position_mm;
  S orientation_rad;
};

template <typename S>
PoseError<S> pose_error(const Pose<S>& measured, const Pose<S>& model) {
  return PoseError<S>{(measured.position_mm - model.position_mm).norm(),
                      log_so3<S>(Mat3<S>(measured.rotation * model.rotation.transpose())).norm()};
}

}  // namespace cdcr::model
