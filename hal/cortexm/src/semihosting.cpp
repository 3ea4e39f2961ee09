#include "cdcr/cortexm/semihosting.hpp"

namespace cdcr::baremetal {
namespace {

constexpr int kSysWrite0 = 0x04;
constexpr int kSysExitExtended = 0x20;
// ADP_Stopped_ApplicationExit: with SYS_EXIT_EXTENDED the second word is the
// status QEMU exits with (plain SYS_EXIT can only say 0 or 1).
constexpr std::uint32_t kApplicationExit = 0x20026;

int semihosting_call(int operation, const void* argument) {
  register int r0 asm("r0") = operation;
  register const void* r1 asm("r1") = argument;
  asm volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

}  // namespace

// The board's half of cdcr/baremetal/console.hpp.
void console_write(const char* text) { semihosting_call(kSysWrite0, text); }

void exit(int code) {
  const std::uint32_t block[2] = {kApplicationExit, static_cast<std::uint32_t>(code)};
  semihosting_call(kSysExitExtended, block);
  // Without a debugger or QEMU's semihosting there is nobody to exit to.
  for (;;) asm volatile("bkpt 0");
}

}  // namespace cdcr::baremetal
