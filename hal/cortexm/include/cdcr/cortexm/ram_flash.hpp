#pragma once
// The MPS2 boards' stand-in flash: every bare-metal board's RAM flash
// (cdcr/baremetal/ram_flash.hpp).

#include <cdcr/baremetal/ram_flash.hpp>

namespace cdcr::cortexm {

template <std::uint32_t SectorBytes, std::uint32_t SectorCount, std::uint32_t MaxProgramBytes = 256>
using RamFlash = baremetal::RamFlash<SectorBytes, SectorCount, MaxProgramBytes>;

}  // namespace cdcr::cortexm
