#pragma once
// How far a pose of the tested type lies from its long-double reference, for
// the typed model tests (scalar_types.hpp).

#include <algorithm>

#include "cdcr/model/se3.hpp"
#include "scalar_types.hpp"

namespace cdcr::test_support {

// The largest rotation-entry difference, or the position difference relative
// to max(1 mm, |p|), whichever is larger.
template <typename S>
Real relative_distance(const model::Pose<S>& actual, const model::Pose<Real>& expected) {
  const Real rotation = (actual.rotation.template cast<Real>() - expected.rotation).cwiseAbs().maxCoeff();
  const Real position = (actual.position_mm.template cast<Real>() - expected.position_mm).norm() /
                        std::max(Real(1), expected.position_mm.norm());
  return std::max(rotation, position);
}

}  // namespace cdcr::test_support
