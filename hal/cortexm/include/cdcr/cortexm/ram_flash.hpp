#pragma once
// The flash of the QEMU boards, which emulate none that firmware can write:
// a RAM region standing in for it, with the semantics of hal/flash.hpp
// (erase sets 0xFF, program clears bits, each operation busy for a number
// of polls as a real one is busy for milliseconds). Its content lasts as
// long as the board's RAM does, so on QEMU it models the flash within a run,
// not across a power cycle. A board with a flash controller implements
// hal::Flash on it instead.

#include <cstdint>
#include <cstring>

#include <cdcr/hal/flash.hpp>

namespace cdcr::cortexm {

template <std::uint32_t SectorBytes, std::uint32_t SectorCount, std::uint32_t MaxProgramBytes = 256>
class RamFlash final : public hal::Flash {
 public:
  // Polls an operation stays busy.
  static constexpr std::uint32_t kErasePolls = 4;
  static constexpr std::uint32_t kProgramPolls = 1;

  RamFlash() { std::memset(bytes_, 0xFF, sizeof(bytes_)); }

  std::uint32_t sector_bytes() const override { return SectorBytes; }
  std::uint32_t sector_count() const override { return SectorCount; }
  std::uint32_t max_program_bytes() const override { return MaxProgramBytes; }
  const std::uint8_t* read() const override { return bytes_; }

  hal::FlashStatus start_erase(std::uint32_t sector) override {
    if (busy_polls_ > 0) return hal::FlashStatus::busy;
    if (sector >= SectorCount) return hal::FlashStatus::bad_range;
    std::memset(bytes_ + sector * SectorBytes, 0xFF, SectorBytes);
    busy_polls_ = kErasePolls;
    return hal::FlashStatus::ok;
  }

  hal::FlashStatus start_program(std::uint32_t offset, const std::uint8_t* data, std::uint32_t size) override {
    if (busy_polls_ > 0) return hal::FlashStatus::busy;
    if (size == 0 || size > MaxProgramBytes || offset >= kBytes || size > kBytes - offset ||
        offset / SectorBytes != (offset + size - 1) / SectorBytes) {
      return hal::FlashStatus::bad_range;
    }
    for (std::uint32_t i = 0; i < size; ++i) bytes_[offset + i] &= data[i];
    busy_polls_ = kProgramPolls;
    return hal::FlashStatus::ok;
  }

  hal::FlashStatus poll() override {
    if (busy_polls_ == 0) return hal::FlashStatus::ok;
    busy_polls_ -= 1;
    return hal::FlashStatus::busy;
  }

 private:
  static constexpr std::uint32_t kBytes = SectorBytes * SectorCount;
  alignas(8) std::uint8_t bytes_[kBytes];
  std::uint32_t busy_polls_ = 0;
};

}  // namespace cdcr::cortexm
