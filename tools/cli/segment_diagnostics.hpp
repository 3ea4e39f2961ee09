#pragma once
// The model reports a failure as a bare Status; a person at the command line
// needs to know which segment and which numbers caused it. These wrappers run
// the model and, when it refuses, find the offending segment and throw an
// InputError that says so.

#include <string>
#include <string_view>

#include <cdcr/model/chain.hpp>

namespace cdcr::cli {

// Segments are numbered from 1 in every message, as on the robot.
std::string describe_segment_cables(model::Status status, int segment_number,
                                    const model::SegmentCables<double>& cables_mm,
                                    const model::SegmentGeometry<double>& geometry);

std::string describe_segment_joints(model::Status status, int segment_number,
                                    const model::SegmentJoints<double>& joints,
                                    const model::SegmentGeometry<double>& geometry);

model::JointVector<double> joints_from_cables_checked(const model::CableVector<double>& cables_mm,
                                                      const model::RobotGeometry<double>& geometry);

// `source` names where the joints came from (a flag, or "solution") and
// prefixes the message.
void check_joints_or_throw(const model::JointVector<double>& joints, const model::RobotGeometry<double>& geometry,
                           std::string_view source);

model::CableVector<double> cables_from_joints_checked(const model::JointVector<double>& joints,
                                                      const model::RobotGeometry<double>& geometry,
                                                      std::string_view source);

}  // namespace cdcr::cli
