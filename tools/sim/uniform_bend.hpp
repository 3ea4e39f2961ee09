#pragma once
// Every segment bent by the same angle towards the same direction: the pose
// family of the demo's streamed circle (cdcr-runtime --sim --circle) and of
// the IK bench's circle-start target.

#include <cdcr/model/chain.hpp>

namespace cdcr::sim {

inline model::JointVector<double> uniform_bend_joints(const model::RobotGeometry<double>& geometry, double bend_rad,
                                                      double direction_rad) {
  model::JointVector<double> joints(2 * geometry.segment_count);
  for (int s = 0; s < geometry.segment_count; ++s) {
    joints[2 * s] = direction_rad;
    joints[2 * s + 1] = bend_rad;
  }
  return joints;
}

// The uniform bend that puts the nominal tip radius_mm off the base's axis,
// by bisection up to the first segment's limit.
inline double uniform_bend_for_tip_radius(const model::RobotGeometry<double>& geometry, double radius_mm) {
  double low = 0, high = geometry.segments[0].theta_max_rad;
  for (int i = 0; i < 60; ++i) {
    model::Pose<double> tip;
    model::forward_kinematics(uniform_bend_joints(geometry, 0.5 * (low + high), 0.0), geometry, tip);
    (tip.position_mm.head<2>().norm() < radius_mm ? low : high) = 0.5 * (low + high);
  }
  return 0.5 * (low + high);
}

}  // namespace cdcr::sim
