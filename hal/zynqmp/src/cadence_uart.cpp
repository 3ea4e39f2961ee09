#include "cdcr/zynqmp/cadence_uart.hpp"

namespace cdcr::zynqmp {
namespace {

// Register offsets (UG1085, UART registers).
enum RegisterOffset : std::uint32_t {
  kControl = 0x00,        // XUARTPS_CR
  kMode = 0x04,           // XUARTPS_MR
  kBaudGenerator = 0x18,  // XUARTPS_BAUDGEN
  kChannelStatus = 0x2C,  // XUARTPS_SR
  kFifo = 0x30,           // XUARTPS_FIFO
  kBaudDivider = 0x34,    // XUARTPS_BAUDDIV
};

constexpr std::uint32_t kControlRxReset = 1u << 0;
constexpr std::uint32_t kControlTxReset = 1u << 1;
constexpr std::uint32_t kControlRxEnable = 1u << 2;
constexpr std::uint32_t kControlTxEnable = 1u << 4;
// Mode: normal channel, 1 stop bit, no parity (PAR = 0b1xx), 8 data bits,
// reference clock undivided.
constexpr std::uint32_t kModeNoParity8N1 = 0x4u << 3;
// 115200 baud from the 100 MHz UART reference clock:
// 100 MHz / (124 * (6 + 1)) = 115207 baud.
constexpr std::uint32_t kBaudGenerator115200 = 124;
constexpr std::uint32_t kBaudDivider115200 = 6;

constexpr std::uint32_t kStatusTxEmpty = 1u << 3;
constexpr std::uint32_t kStatusTxFull = 1u << 4;

}  // namespace

void CadenceUart::init() {
  reg(kControl) = kControlRxReset | kControlTxReset;
  reg(kMode) = kModeNoParity8N1;
  reg(kBaudGenerator) = kBaudGenerator115200;
  reg(kBaudDivider) = kBaudDivider115200;
  reg(kControl) = kControlRxEnable | kControlTxEnable;
}

void CadenceUart::write_char(char character) {
  while ((reg(kChannelStatus) & kStatusTxFull) != 0) {
  }
  reg(kFifo) = static_cast<std::uint8_t>(character);
}

void CadenceUart::write(const char* text) {
  for (; *text != '\0'; ++text) write_char(*text);
}

void CadenceUart::flush() {
  while ((reg(kChannelStatus) & kStatusTxEmpty) == 0) {
  }
}

}  // namespace cdcr::zynqmp
