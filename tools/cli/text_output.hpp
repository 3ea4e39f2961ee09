#pragma once
// Human-readable tables shared by the commands. Angles in rad, lengths in mm,
// six decimals: enough to compare with the paper's four.

#include <string>

#include <cdcr/model/geometry.hpp>
#include <cdcr/model/se3.hpp>
#include <cdcr/model/types.hpp>

namespace cdcr::cli {

std::string format_joints_table(const model::JointVector<double>& joints);
// Each segment's cables on a line (a dash for the l4 a segment of three has not).
std::string format_cables_table(const model::CableVector<double>& cables_mm,
                                const model::RobotGeometry<double>& geometry);
// The 4x4 homogeneous matrix [R p; 0 0 0 1], p in mm.
std::string format_pose(const model::Pose<double>& pose);

}  // namespace cdcr::cli
