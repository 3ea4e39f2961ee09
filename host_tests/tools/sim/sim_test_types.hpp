#pragma once
// The names the simulator's tests speak in: its double-precision model types
// and the prototype robot it simulates by default.

#include <cdcr/model/chain.hpp>
#include <cdcr/model/units.hpp>

namespace cdcr::sim::test_types {

using Geometry = model::RobotGeometry<double>;
using Pose = model::Pose<double>;
using Cables = model::CableVector<double>;
using Joints = model::JointVector<double>;
using Vec3 = model::Vec3<double>;

inline const Geometry kPrototype = Geometry::prototype();

}  // namespace cdcr::sim::test_types
