#pragma once
// Console lines built without printf: newlib's formatted output allocates,
// and a board build links no heap. The appends are out of line
// (console_line.cpp): inlined at every use, unrolled, they cost the M7's
// program kilobytes of code for lines printed once.

#include "cdcr/firmware/capacity.hpp"

namespace cdcr::firmware {

class ConsoleLine {
 public:
  ConsoleLine& operator<<(const char* text);
  ConsoleLine& operator<<(unsigned value);
  ConsoleLine& operator<<(int value);
  const char* c_str() const { return text_; }

 private:
  char text_[kConsoleLineBytes] = {};
  int length_ = 0;
};

}  // namespace cdcr::firmware
