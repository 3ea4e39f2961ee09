#pragma once
// The R5F board's console on uart0 (the Cadence UART at 0xFF000000), and the
// exit status a program under QEMU ends with. Text goes to the UART only;
// semihosting serves the exit status alone, so the board reports the same way
// with or without a debugger.

#include <cstdint>

namespace cdcr::zynqmp {

// Exit statuses that tell a failing check apart from a crash (the same as
// the Cortex-M boards').
enum class ExitCode : int {
  success = 0,
  failure = 1,
  hard_fault = 3,
  assertion_failed = 4,
  heap_used = 5,
};

// The UART is set up by the start-up code before main.
void console_init();
void console_write(const char* text);
// Appends a decimal integer; no printf, which would pull in the heap.
void console_write_int(std::int32_t value);
void console_write_hex(std::uint32_t value);

// Drains the UART, then asks QEMU (semihosting SYS_EXIT_EXTENDED) to exit
// with `code`; without QEMU's semihosting the core stops here.
[[noreturn]] void exit(ExitCode code);
[[noreturn]] void exit(int code);

}  // namespace cdcr::zynqmp
