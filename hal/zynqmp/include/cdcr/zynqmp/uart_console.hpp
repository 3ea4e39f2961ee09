#pragma once
// The runtime's log lines on the board's UART (console.hpp).

#include <cdcr/hal/console.hpp>

#include "cdcr/zynqmp/console.hpp"

namespace cdcr::zynqmp {

class UartConsole final : public hal::Console {
 public:
  void write_line(const char* line) override {
    console_write(line);
    console_write("\n");
  }
};

}  // namespace cdcr::zynqmp
