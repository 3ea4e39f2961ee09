#include "cdcr/firmware/console_line.hpp"

namespace cdcr::firmware {

ConsoleLine& ConsoleLine::operator<<(const char* text) {
  while (*text != '\0' && length_ + 1 < kConsoleLineBytes) text_[length_++] = *text++;
  text_[length_] = '\0';
  return *this;
}

ConsoleLine& ConsoleLine::operator<<(unsigned value) {
  char digits[10];
  int count = 0;
  do {
    digits[count++] = static_cast<char>('0' + value % 10);
    value /= 10;
  } while (value != 0);
  while (count > 0 && length_ + 1 < kConsoleLineBytes) text_[length_++] = digits[--count];
  text_[length_] = '\0';
  return *this;
}

ConsoleLine& ConsoleLine::operator<<(int value) {
  if (value >= 0) return *this << unsigned(value);
  *this << "-";
  return *this << (0u - unsigned(value));
}

}  // namespace cdcr::firmware
