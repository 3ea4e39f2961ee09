#pragma once
// Human-readable log lines (a UART on a board, stderr on the host).

namespace cdcr::hal {

class Console {
 public:
  // `line` is NUL-terminated and carries no newline; the backend ends the line.
  virtual void write_line(const char* line) = 0;

 protected:
  Console() = default;
  ~Console() = default;
  Console(const Console&) = default;
  Console& operator=(const Console&) = default;
};

}  // namespace cdcr::hal
