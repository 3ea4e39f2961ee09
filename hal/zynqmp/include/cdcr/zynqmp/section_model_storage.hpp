#pragma once
// The model image in its own section, `.cdcr_model`, bounded by the linker
// script's __cdcr_model_start__ and __cdcr_model_end__ (zcu102_r5f.ld), read
// in place; an empty section reads as no image. The same contract as the
// Cortex-M boards' FlashModelStorage.

#include <cstdint>

#include <cdcr/hal/model_storage.hpp>

extern "C" {
extern const std::uint8_t __cdcr_model_start__[];
extern const std::uint8_t __cdcr_model_end__[];
}

namespace cdcr::zynqmp {

class SectionModelStorage final : public hal::ModelStorage {
 public:
  hal::MemoryRegion model_region() const override {
    const auto size = static_cast<std::size_t>(__cdcr_model_end__ - __cdcr_model_start__);
    if (size == 0) return {};
    return {__cdcr_model_start__, size};
  }
};

}  // namespace cdcr::zynqmp
