#pragma once
// A NOR flash modelled in memory, with the semantics of flash.hpp: erase sets
// 0xFF, program clears bits, one operation at a time, each busy for a number
// of polls as a real one is busy for milliseconds. The memory is the
// caller's, so a board keeps it in a static array and the simulator in a
// vector; both are this one model.
//
// A power cut is a hook: before each operation, admit() may let it run only
// in part (the bytes it is allowed to change) or refuse it; the simulated
// flash uses it to tear an operation and lose the power.

#include <cstdint>
#include <cstring>

#include "cdcr/hal/flash.hpp"

namespace cdcr::hal {

struct NorFlashTiming {
  std::uint32_t erase_polls = 4;    // polls an erase reports busy
  std::uint32_t program_polls = 1;  // likewise a program
};

class NorFlashModel : public Flash {
 public:
  using Timing = NorFlashTiming;

  NorFlashModel(std::uint8_t* bytes, std::uint32_t sector_bytes, std::uint32_t sector_count,
                std::uint32_t max_program_bytes, Timing timing = NorFlashTiming{})
      : bytes_(bytes),
        sector_bytes_(sector_bytes),
        sector_count_(sector_count),
        max_program_bytes_(max_program_bytes),
        timing_(timing) {}
  NorFlashModel(const NorFlashModel&) = delete;
  NorFlashModel& operator=(const NorFlashModel&) = delete;

  std::uint32_t sector_bytes() const override { return sector_bytes_; }
  std::uint32_t sector_count() const override { return sector_count_; }
  std::uint32_t max_program_bytes() const override { return max_program_bytes_; }
  const std::uint8_t* read() const override { return bytes_; }

  FlashStatus start_erase(std::uint32_t sector) override {
    if (const FlashStatus s = refusal(); s != FlashStatus::ok) return s;
    if (sector >= sector_count_) return FlashStatus::bad_range;
    std::uint32_t bytes = sector_bytes_;
    if (!admit(bytes)) return FlashStatus::failed;
    std::memset(bytes_ + sector * sector_bytes_, 0xFF, bytes);
    erases_ += 1;
    busy_polls_ = timing_.erase_polls;
    return FlashStatus::ok;
  }

  FlashStatus start_program(std::uint32_t offset, const std::uint8_t* data, std::uint32_t size) override {
    if (const FlashStatus s = refusal(); s != FlashStatus::ok) return s;
    if (size == 0 || size > max_program_bytes_ || offset >= size_bytes() || size > size_bytes() - offset ||
        offset / sector_bytes_ != (offset + size - 1) / sector_bytes_) {
      return FlashStatus::bad_range;
    }
    std::uint32_t bytes = size;
    if (!admit(bytes)) return FlashStatus::failed;
    std::uint8_t* target = bytes_ + offset;
    for (std::uint32_t i = 0; i < bytes; ++i) target[i] &= data[i];
    programs_ += 1;
    busy_polls_ = timing_.program_polls;
    return FlashStatus::ok;
  }

  FlashStatus poll() override {
    if (unpowered()) return FlashStatus::failed;
    if (busy_polls_ == 0) return FlashStatus::ok;
    busy_polls_ -= 1;
    return FlashStatus::busy;
  }

  std::uint64_t erases() const { return erases_; }
  std::uint64_t programs() const { return programs_; }

 protected:
  ~NorFlashModel() = default;

  // An operation about to change `bytes` bytes: false refuses it (failed),
  // or it may lower `bytes` to carry out only their first part.
  virtual bool admit(std::uint32_t& bytes) {
    static_cast<void>(bytes);
    return true;
  }
  // No operation runs and none can start (a flash without power).
  virtual bool unpowered() const { return false; }
  void cancel_operation() { busy_polls_ = 0; }
  std::uint8_t* bytes() { return bytes_; }

 private:
  FlashStatus refusal() const {
    if (unpowered()) return FlashStatus::failed;
    if (busy_polls_ > 0) return FlashStatus::busy;
    return FlashStatus::ok;
  }

  std::uint8_t* bytes_;
  std::uint32_t sector_bytes_;
  std::uint32_t sector_count_;
  std::uint32_t max_program_bytes_;
  Timing timing_;
  std::uint32_t busy_polls_ = 0;
  std::uint64_t erases_ = 0;
  std::uint64_t programs_ = 0;
};

}  // namespace cdcr::hal
