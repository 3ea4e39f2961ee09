#pragma once
// The flash of the QEMU boards (the MPS2 boards, the R5F's zcu102), which
// emulate none that firmware can write: a RAM region standing in for it,
// the HAL's NOR flash model over a static array. Its content lasts as long as the board's RAM does, so on QEMU it
// models the flash within a run, not across a power cycle. A board with a
// flash controller implements hal::Flash on it instead.

#include <cstdint>
#include <cstring>

#include <cdcr/hal/nor_flash_model.hpp>

namespace cdcr::baremetal {

template <std::uint32_t SectorBytes, std::uint32_t SectorCount, std::uint32_t MaxProgramBytes = 256>
class RamFlash final : public hal::NorFlashModel {
 public:
  // Polls an operation stays busy.
  static constexpr std::uint32_t kErasePolls = hal::NorFlashTiming{}.erase_polls;
  static constexpr std::uint32_t kProgramPolls = hal::NorFlashTiming{}.program_polls;

  RamFlash() : NorFlashModel(storage_, SectorBytes, SectorCount, MaxProgramBytes) {
    std::memset(storage_, 0xFF, sizeof(storage_));
  }

 private:
  alignas(8) std::uint8_t storage_[SectorBytes * SectorCount];
};

}  // namespace cdcr::baremetal
