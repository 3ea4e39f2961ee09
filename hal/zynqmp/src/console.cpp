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

}  // namespace cdcr::zynqmp

// The board's half of cdcr/baremetal/console.hpp.
namespace cdcr::baremetal {

void console_write(const char* text) { zynqmp::uart0().write(text); }

void exit(int code) {
  zynqmp::uart0().flush();
  const std::uint32_t block[2] = {zynqmp::kApplicationExit, static_cast<std::uint32_t>(code)};
  cdcr_zynqmp_semihosting_call(zynqmp::kSysExitExtended, block);
  for (;;) asm volatile("wfi");
}

}  // namespace cdcr::baremetal
