#pragma once
// The accuracy of a set of poses against their references, as the paper
// reports it (eq. 20, Tables 2-3): the mean and the largest position error in
// mm and orientation error in degrees. A report, so in double: the host's
// evaluation, the simulator's initial error and noise floor, and the boards'
// golden checks all widen their poses first.

#include <algorithm>
#include <cstddef>

#include "cdcr/model/compensation.hpp"
#include "cdcr/model/se3.hpp"
#include "cdcr/model/units.hpp"

namespace cdcr::model {

struct PoseErrorSummary {
  double mean_position_mm = 0.0;
  double mean_orientation_deg = 0.0;
  double max_position_mm = 0.0;
  double max_orientation_deg = 0.0;
};

// Over the `count` pairs (reference[i], poses[i]); all zero when count is 0.
inline PoseErrorSummary summarize_pose_errors(const Pose<double>* reference, const Pose<double>* poses,
                                              std::size_t count) {
  PoseErrorSummary summary;
  if (count == 0) return summary;
  for (std::size_t i = 0; i < count; ++i) {
    const PoseError<double> e = pose_error(reference[i], poses[i]);
    const double orientation_deg = e.orientation_rad * kDegreesPerRadian;
    summary.mean_position_mm += e.position_mm;
    summary.mean_orientation_deg += orientation_deg;
    summary.max_position_mm = std::max(summary.max_position_mm, e.position_mm);
    summary.max_orientation_deg = std::max(summary.max_orientation_deg, orientation_deg);
  }
  summary.mean_position_mm /= static_cast<double>(count);
  summary.mean_orientation_deg /= static_cast<double>(count);
  return summary;
}

}  // namespace cdcr::model
