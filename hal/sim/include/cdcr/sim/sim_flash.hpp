#pragma once
// The simulated board's flash (hal/flash.hpp): sectors in memory with NOR
// semantics (erase sets 0xFF, program clears bits), operations that take a
// number of polls to finish (one poll per runtime cycle), and the fault the
// power-fail tests inject: a power loss during the k-th operation.
//
// Power loss: power_loss_at(k, cut) makes the k-th operation started from
// then on (k = 1 is the next one) the last the flash performs:
//   Cut::torn      it is half done: an erase sets the first half of the
//                  sector to 0xFF, a program writes the first half of its
//                  bytes (rounded down); the rest keeps its old content.
//   Cut::complete  it is done, but the power goes before it reports done.
// After the loss every operation fails and power_lost() is true; the test
// then builds a new runtime on the same flash, which is the reboot.
// MCUboot's simulator counts flash operations the same way to cut an
// upgrade at every point.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

#include <cdcr/hal/flash.hpp>

namespace cdcr::sim {

struct SimFlashTiming {
  std::uint32_t erase_polls = 4;    // polls an erase reports busy
  std::uint32_t program_polls = 1;  // likewise a program
};

class SimFlash final : public hal::Flash {
 public:
  enum class Cut : std::uint8_t { torn, complete };
  using Timing = SimFlashTiming;

  SimFlash(std::uint32_t sector_bytes, std::uint32_t sector_count, std::uint32_t max_program_bytes = 256,
           Timing timing = SimFlashTiming{})
      : sector_bytes_(sector_bytes),
        sector_count_(sector_count),
        max_program_bytes_(max_program_bytes),
        timing_(timing),
        words_((std::size_t(sector_bytes) * sector_count + 7) / 8, ~std::uint64_t{0}) {}

  std::uint32_t sector_bytes() const override { return sector_bytes_; }
  std::uint32_t sector_count() const override { return sector_count_; }
  std::uint32_t max_program_bytes() const override { return max_program_bytes_; }
  const std::uint8_t* read() const override { return reinterpret_cast<const std::uint8_t*>(words_.data()); }

  hal::FlashStatus start_erase(std::uint32_t sector) override {
    if (power_lost_) return hal::FlashStatus::failed;
    if (busy_polls_ > 0) return hal::FlashStatus::busy;
    if (sector >= sector_count_) return hal::FlashStatus::bad_range;
    if (!begin_operation()) return hal::FlashStatus::failed;
    std::uint32_t bytes = sector_bytes_;
    if (cutting_now_ && cut_ == Cut::torn) bytes /= 2;
    std::memset(bytes_at(sector * sector_bytes_), 0xFF, bytes);
    erases_ += 1;
    busy_polls_ = timing_.erase_polls;
    return hal::FlashStatus::ok;
  }

  hal::FlashStatus start_program(std::uint32_t offset, const std::uint8_t* data, std::uint32_t size) override {
    if (power_lost_) return hal::FlashStatus::failed;
    if (busy_polls_ > 0) return hal::FlashStatus::busy;
    if (size == 0 || size > max_program_bytes_ || offset >= size_bytes() || size > size_bytes() - offset ||
        offset / sector_bytes_ != (offset + size - 1) / sector_bytes_) {
      return hal::FlashStatus::bad_range;
    }
    if (!begin_operation()) return hal::FlashStatus::failed;
    std::uint32_t bytes = size;
    if (cutting_now_ && cut_ == Cut::torn) bytes /= 2;
    std::uint8_t* target = bytes_at(offset);
    for (std::uint32_t i = 0; i < bytes; ++i) target[i] &= data[i];
    programs_ += 1;
    busy_polls_ = timing_.program_polls;
    return hal::FlashStatus::ok;
  }

  hal::FlashStatus poll() override {
    if (power_lost_) return hal::FlashStatus::failed;
    if (busy_polls_ > 0) {
      busy_polls_ -= 1;
      return hal::FlashStatus::busy;
    }
    return hal::FlashStatus::ok;
  }

  // The fault: see the top of the file. k = 0 cancels it.
  void power_loss_at(std::uint64_t k, Cut cut) {
    loss_at_ = k == 0 ? 0 : operations_ + k;
    cut_ = cut;
  }
  bool power_lost() const { return power_lost_; }
  // Power back on: the flash keeps its content, nothing is running.
  void power_on() {
    power_lost_ = false;
    busy_polls_ = 0;
    loss_at_ = 0;
  }

  std::uint64_t operations() const { return operations_; }
  std::uint64_t erases() const { return erases_; }
  std::uint64_t programs() const { return programs_; }

  // Test access: write bytes as a programmer would (no semantics, no count).
  void write_raw(std::uint32_t offset, const std::uint8_t* data, std::uint32_t size) {
    std::memcpy(bytes_at(offset), data, size);
  }
  std::uint8_t* raw() { return bytes_at(0); }

 private:
  std::uint8_t* bytes_at(std::uint32_t offset) { return reinterpret_cast<std::uint8_t*>(words_.data()) + offset; }

  // Counts the operation; false when the power is already gone.
  bool begin_operation() {
    cutting_now_ = false;
    if (power_lost_) return false;
    operations_ += 1;
    if (loss_at_ != 0 && operations_ == loss_at_) {
      cutting_now_ = true;
      power_lost_ = true;
    }
    return true;
  }

  std::uint32_t sector_bytes_;
  std::uint32_t sector_count_;
  std::uint32_t max_program_bytes_;
  Timing timing_;
  std::vector<std::uint64_t> words_;
  std::uint32_t busy_polls_ = 0;
  std::uint64_t operations_ = 0;
  std::uint64_t erases_ = 0;
  std::uint64_t programs_ = 0;
  std::uint64_t loss_at_ = 0;
  Cut cut_ = Cut::torn;
  bool cutting_now_ = false;
  bool power_lost_ = false;
};

}  // namespace cdcr::sim
