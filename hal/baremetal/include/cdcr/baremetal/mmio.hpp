#pragma once
// A 32-bit memory-mapped register of a peripheral at `base`.

#include <cstdint>

namespace cdcr::baremetal {

inline volatile std::uint32_t& register_at(std::uintptr_t base, std::uint32_t offset) {
  return *reinterpret_cast<volatile std::uint32_t*>(base + offset);
}

}  // namespace cdcr::baremetal
