#include "cdcr/baremetal/console.hpp"

namespace cdcr::baremetal {

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

}  // namespace cdcr::baremetal
