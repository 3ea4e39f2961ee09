#pragma once
// Console lines on a stdio stream (stderr by default, so they never mix with
// a tool's own output on stdout).

#include <cstdio>

#include <cdcr/hal/console.hpp>

namespace cdcr::linux_host {

class StdioConsole final : public hal::Console {
 public:
  explicit StdioConsole(std::FILE* stream = stderr) : stream_(stream) {}
  void write_line(const char* line) override {
    std::fprintf(stream_, "%s\n", line);
    std::fflush(stream_);
  }

 private:
  std::FILE* stream_;
};

}  // namespace cdcr::linux_host
