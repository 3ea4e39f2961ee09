#pragma once
// The model image in its own section, `.cdcr_model` (zcu102_r5f.ld), read in
// place: the same contract as the Cortex-M boards' FlashModelStorage
// (cdcr/baremetal/section_model_storage.hpp).

#include <cdcr/baremetal/section_model_storage.hpp>

namespace cdcr::zynqmp {

using SectionModelStorage = baremetal::SectionModelStorage;

}  // namespace cdcr::zynqmp
