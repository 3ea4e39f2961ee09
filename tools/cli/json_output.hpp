#pragma once
// JSON encodings shared by the commands' --json output. Numbers are written
// with full double precision so the output can be fed back without loss.

#include <nlohmann/json.hpp>

#include <cdcr/model/geometry.hpp>
#include <cdcr/model/se3.hpp>
#include <cdcr/model/types.hpp>

namespace cdcr::cli {

// Objects keep their keys in the documented order rather than sorted.
using Json = nlohmann::ordered_json;

// [[alpha_1, theta_1], [alpha_2, theta_2], ...] in rad.
Json joints_to_json(const model::JointVector<double>& joints);
// [[l1, l2, l3, l4] of segment 1, ...] in mm.
// One array per segment, of its cables.
Json cables_to_json(const model::CableVector<double>& cables_mm, const model::RobotGeometry<double>& geometry);
// The 4x4 matrix [R p; 0 0 0 1] as four rows, p in mm.
Json pose_to_json(const model::Pose<double>& pose);

}  // namespace cdcr::cli
