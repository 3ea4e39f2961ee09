#include "cdcr/zynqmp/console.hpp"

#include "cdcr/zynqmp/cadence_uart.hpp"
#include "cdcr/zynqmp/zcu102.hpp"

extern "C" int cdcr_zynqmp_semihosting_call(int operation, const void* argument);  // vectors.S

namespace cdcr::zynqmp {
namespace {

// Constant-initialised (constexpr constructor): usable before and during the
// static constructors.
CadenceUart uart0_instance{kUart0Base};
CadenceUart& uart0() { return uart0_instance; }

constexpr int kSysExitExtended = 0x20;
// ADP_Stopped_ApplicationExit: with SYS_EXIT_EXTENDED the second word is the
// status QEMU exits with.
constexpr std::uint32_t kApplicationExit = 0x20026;

}  // namespace

void console_init() { uart0().init(); }

void console_write(const char* text) { uart0().write(text); }

void console_write_int(std::int32_t value) {
  char text[12];
  char* at = text + sizeof(text);
  *--at = '\0';
  // Negate in unsigned arithmetic so INT32_MIN survives.
  std::uint32_t magnitude = value < 0 ? 0u - static_cast<std::uint32_t>(value) : static_cast<std::uint32_t>(value);
  do {
    *--at = static_cast<char>('0' + magnitude % 10);
    magnitude /= 10;
  } while (magnitude != 0);
  if (value < 0) *--at = '-';
  console_write(at);
}

void console_write_hex(std::uint32_t value) {
  char text[11] = "0x";
  for (int digit = 0; digit < 8; ++digit) {
    const std::uint32_t nibble = (value >> (28 - 4 * digit)) & 0xFu;
    text[2 + digit] = static_cast<char>(nibble < 10 ? '0' + nibble : 'a' + nibble - 10);
  }
  text[10] = '\0';
  console_write(text);
}

void exit(int code) {
  uart0().flush();
  const std::uint32_t block[2] = {kApplicationExit, static_cast<std::uint32_t>(code)};
  cdcr_zynqmp_semihosting_call(kSysExitExtended, block);
  for (;;) asm volatile("wfi");
}

void exit(ExitCode code) { exit(static_cast<int>(code)); }

}  // namespace cdcr::zynqmp
