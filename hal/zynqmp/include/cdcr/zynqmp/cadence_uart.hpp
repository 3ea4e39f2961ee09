#pragma once
// The Cadence UART of the Zynq UltraScale+ (UG1085, "UART"), transmit side
// only, polled: the board's console. 115200 baud, 8 data bits, no parity,
// one stop bit.

#include <cstdint>

#include <cdcr/baremetal/mmio.hpp>

namespace cdcr::zynqmp {

class CadenceUart {
 public:
  explicit constexpr CadenceUart(std::uintptr_t base) : base_(base) {}

  // Resets both FIFOs and enables the transmitter and receiver.
  void init();
  // Waits for room in the transmit FIFO before each character.
  void write(const char* text);
  void write_char(char character);
  // Returns once the transmit FIFO has drained, so nothing is lost when the
  // program ends right after.
  void flush();

 private:
  volatile std::uint32_t& reg(std::uint32_t offset) const { return baremetal::register_at(base_, offset); }

  std::uintptr_t base_;
};

}  // namespace cdcr::zynqmp
