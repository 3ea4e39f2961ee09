#pragma once
// The runtime's log lines over semihosting. On a board without a debugger
// attached, a UART console takes its place (hal/README.md).

#include <cdcr/hal/console.hpp>

#include "cdcr/cortexm/semihosting.hpp"

namespace cdcr::cortexm {

class SemihostingConsole final : public hal::Console {
 public:
  void write_line(const char* line) override {
    console_write(line);
    console_write("\n");
  }
};

}  // namespace cdcr::cortexm
