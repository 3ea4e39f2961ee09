#pragma once
// The model image in its own flash section, `.cdcr_model` (mps2.ld), read in
// place (cdcr/baremetal/section_model_storage.hpp).

#include <cdcr/baremetal/section_model_storage.hpp>

namespace cdcr::cortexm {

using FlashModelStorage = baremetal::SectionModelStorage;

}  // namespace cdcr::cortexm
