#pragma once
// Console output and exit status through ARM semihosting (bkpt 0xAB), which
// QEMU answers when run with -semihosting-config enable=on. This is how a
// program under QEMU reports to the test that started it.

#include <cstdint>

namespace cdcr::cortexm {

// Exit statuses that tell a failing check apart from a crash.
enum class ExitCode : int {
  success = 0,
  failure = 1,
  hard_fault = 3,
  assertion_failed = 4,
  heap_used = 5,
};

void console_write(const char* text);
// Appends a decimal integer; no printf, which would pull in the heap.
void console_write_int(std::int32_t value);
// A fixed-point decimal with the given number of fraction digits (<= 9).
void console_write_fixed(double value, int fraction_digits);

[[noreturn]] void exit(ExitCode code);
[[noreturn]] void exit(int code);

}  // namespace cdcr::cortexm
