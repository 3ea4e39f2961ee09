#pragma once
// Console lines built without printf: newlib's formatted output allocates,
// and a board build links no heap.

#include "cdcr/firmware/capacity.hpp"

namespace cdcr::firmware {

class ConsoleLine {
 public:
  ConsoleLine& operator<<(const char* text) {
    while (*text != '\0' && length_ + 1 < kConsoleLineBytes) text_[length_++] = *text++;
    text_[length_] = '\0';
    return *this;
  }
  ConsoleLine& operator<<(unsigned value) {
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
  const char* c_str() const { return text_; }

 private:
  char text_[kConsoleLineBytes] = {};
  int length_ = 0;
};

}  // namespace cdcr::firmware
