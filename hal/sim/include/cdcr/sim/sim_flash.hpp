#pragma once
// The simulated board's flash: the HAL's NOR flash model (hal/nor_flash_model.hpp)
// over memory of any size, operations that take a number of polls to finish
// (one poll per runtime cycle), and the fault the power-fail tests inject: a
// power loss during the k-th operation.
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

#include <cstdint>
#include <cstring>
#include <vector>

#include <cdcr/hal/nor_flash_model.hpp>

namespace cdcr::sim {

using SimFlashTiming = hal::NorFlashTiming;

namespace detail {
// The memory, constructed before the flash model that is handed its address.
struct SimFlashMemory {
  explicit SimFlashMemory(std::size_t bytes) : words((bytes + 7) / 8, ~std::uint64_t{0}) {}
  std::vector<std::uint64_t> words;
};
}  // namespace detail

class SimFlash final : private detail::SimFlashMemory, public hal::NorFlashModel {
 public:
  enum class Cut : std::uint8_t { torn, complete };
  using Timing = SimFlashTiming;

  SimFlash(std::uint32_t sector_bytes, std::uint32_t sector_count, std::uint32_t max_program_bytes = 256,
           Timing timing = SimFlashTiming{})
      : SimFlashMemory(std::size_t(sector_bytes) * sector_count),
        NorFlashModel(reinterpret_cast<std::uint8_t*>(words.data()), sector_bytes, sector_count, max_program_bytes,
                      timing) {}

  // The fault: see the top of the file. k = 0 cancels it.
  void power_loss_at(std::uint64_t k, Cut cut) {
    loss_at_ = k == 0 ? 0 : operations_ + k;
    cut_ = cut;
  }
  bool power_lost() const { return power_lost_; }
  // Power back on: the flash keeps its content, nothing is running.
  void power_on() {
    power_lost_ = false;
    cancel_operation();
    loss_at_ = 0;
  }

  std::uint64_t operations() const { return operations_; }

  // Test access: write bytes as a programmer would (no semantics, no count).
  void write_raw(std::uint32_t offset, const std::uint8_t* data, std::uint32_t size) {
    std::memcpy(bytes() + offset, data, size);
  }
  std::uint8_t* raw() { return bytes(); }

 private:
  // Counts the operation; the k-th is torn or completed, and is the last.
  bool admit(std::uint32_t& bytes) override {
    operations_ += 1;
    if (loss_at_ != 0 && operations_ == loss_at_) {
      power_lost_ = true;
      if (cut_ == Cut::torn) bytes /= 2;
    }
    return true;
  }
  bool unpowered() const override { return power_lost_; }

  std::uint64_t operations_ = 0;
  std::uint64_t loss_at_ = 0;
  Cut cut_ = Cut::torn;
  bool power_lost_ = false;
};

}  // namespace cdcr::sim
