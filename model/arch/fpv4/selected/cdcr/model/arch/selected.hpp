#pragma once
// The architecture the build selected (CDCR_MODEL_ARCH=fpv4, the Cortex-M4F):
// the C++ loops with VLDM block loads.

#include "cdcr/model/arch/fpv4.hpp"

namespace cdcr::model::arch {
using Selected = Fpv4;
}  // namespace cdcr::model::arch
