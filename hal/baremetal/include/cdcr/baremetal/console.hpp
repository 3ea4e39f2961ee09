#pragma once
// The console and the exit status of a bare-metal board (the Cortex-M boards'
// semihosting, the R5F board's UART). A board defines console_write and
// exit(int); the number formatting here is the same on every board.

#include <cstdint>

namespace cdcr::baremetal {

// Exit statuses that tell a failing check apart from a crash.
enum class ExitCode : int {
  success = 0,
  failure = 1,
  hard_fault = 3,
  assertion_failed = 4,
  heap_used = 5,
  watchdog_expired = 6,  // a board's watchdog ended the program (no reset to emulate)
};

// Defined by the board.
void console_write(const char* text);
[[noreturn]] void exit(int code);

// Appends a decimal integer; no printf, which would pull in the heap.
void console_write_int(std::int32_t value);
// `0x` and eight hexadecimal digits.
void console_write_hex(std::uint32_t value);
// A fixed-point decimal with the given number of fraction digits (<= 9).
void console_write_fixed(double value, int fraction_digits);

[[noreturn]] inline void exit(ExitCode code) { exit(static_cast<int>(code)); }

}  // namespace cdcr::baremetal
