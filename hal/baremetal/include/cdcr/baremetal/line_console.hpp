#pragma once
// The runtime's log lines on a bare-metal board's console (console.hpp).

#include <cdcr/hal/console.hpp>

#include "cdcr/baremetal/console.hpp"

namespace cdcr::baremetal {

class LineConsole final : public hal::Console {
 public:
  void write_line(const char* line) override {
    console_write(line);
    console_write("\n");
  }
};

}  // namespace cdcr::baremetal
