#include "cdcr/cortexm/semihosting.hpp"

namespace cdcr::cortexm {
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

void console_write(const char* text) { semihosting_call(kSysWrite0, text); }

void console_write_int(std::int32_t value) {
  char text[12];
  char* end = text + sizeof(text);
  char* at = end;
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

void console_write_fixed(double value, int fraction_digits) {
  if (!(value == value)) {
    console_write("nan");
    return;
  }
  if (fraction_digits < 0) fraction_digits = 0;
  if (fraction_digits > 9) fraction_digits = 9;
  std::uint32_t unit = 1;
  for (int i = 0; i < fraction_digits; ++i) unit *= 10;
  const bool negative = value < 0;
  double magnitude = negative ? -value : value;
  if (magnitude > 2.0e9) {
    console_write(negative ? "-huge" : "huge");
    return;
  }
  const double scaled = magnitude * unit + 0.5;
  const auto whole = static_cast<std::uint32_t>(scaled / unit);
  const auto fraction = static_cast<std::uint32_t>(scaled - static_cast<double>(whole) * unit);
  if (negative) console_write("-");
  console_write_int(static_cast<std::int32_t>(whole));
  if (fraction_digits == 0) return;
  char text[11];
  text[0] = '.';
  std::uint32_t rest = fraction;
  for (int i = fraction_digits; i >= 1; --i) {
    text[i] = static_cast<char>('0' + rest % 10);
    rest /= 10;
  }
  text[fraction_digits + 1] = '\0';
  console_write(text);
}

void exit(int code) {
  const std::uint32_t block[2] = {kApplicationExit, static_cast<std::uint32_t>(code)};
  semihosting_call(kSysExitExtended, block);
  // Without a debugger or QEMU's semihosting there is nobody to exit to.
  for (;;) asm volatile("bkpt 0");
}

void exit(ExitCode code) { exit(static_cast<int>(code)); }

}  // namespace cdcr::cortexm
