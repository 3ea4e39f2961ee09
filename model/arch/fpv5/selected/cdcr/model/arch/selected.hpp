#pragma once
// The architecture the build selected (CDCR_MODEL_ARCH=fpv5, the Cortex-M7):
// VLDM block loads and the assembly mean loop for 4 segments.

#include "cdcr/model/arch/fpv5.hpp"

namespace cdcr::model::arch {
using Selected = Fpv5;
}  // namespace cdcr::model::arch
