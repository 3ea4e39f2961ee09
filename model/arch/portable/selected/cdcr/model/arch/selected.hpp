#pragma once
// The architecture the build selected (CDCR_MODEL_ARCH=portable, every host
// build): the plain C++ loops.

#include "cdcr/model/arch/portable.hpp"

namespace cdcr::model::arch {
using Selected = Portable;
}  // namespace cdcr::model::arch
