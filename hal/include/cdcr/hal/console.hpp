#pragma once
// Human-readable log lines (a UART on a board, stderr on the host).

#include "cdcr/hal/interface.hpp"

namespace cdcr::hal {

class Console : public Interface {
 public:
  // `line` is NUL-terminated and carries no newline; the backend ends the line.
  virtual void write_line(const char* line) = 0;

 protected:
  ~Console() = default;
};

// Drops every line: for a platform with nowhere to write them (the simulated
// board, whose host program reports on its own).
class NullConsole final : public Console {
 public:
  void write_line(const char*) override {}
};

}  // namespace cdcr::hal
