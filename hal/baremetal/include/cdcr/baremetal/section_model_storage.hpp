#pragma once
// The model image in its own section, `.cdcr_model`, bounded by the linker
// script's __cdcr_model_start__ and __cdcr_model_end__. The image is read in
// place; an empty section reads as no image.
//
// On QEMU the exporter's C array is linked into the section. On a board the
// section is a reserved flash range that `cdcr export --format hex` output is
// flashed to on its own, so a new model needs no new firmware.

#include <cstdint>

#include <cdcr/hal/model_storage.hpp>

extern "C" {
extern const std::uint8_t __cdcr_model_start__[];
extern const std::uint8_t __cdcr_model_end__[];
}

namespace cdcr::baremetal {

class SectionModelStorage final : public hal::ModelStorage {
 public:
  hal::MemoryRegion model_region() const override {
    const auto size = static_cast<std::size_t>(__cdcr_model_end__ - __cdcr_model_start__);
    if (size == 0) return {};
    return {__cdcr_model_start__, size};
  }
};

}  // namespace cdcr::baremetal
