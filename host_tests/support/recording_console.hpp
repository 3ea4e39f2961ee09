#pragma once
// A console that keeps its lines for a test to inspect (host only: it
// allocates).

#include <string>
#include <vector>

#include <cdcr/hal/console.hpp>

namespace cdcr::test_support {

class RecordingConsole final : public hal::Console {
 public:
  void write_line(const char* line) override { lines.emplace_back(line); }
  std::vector<std::string> lines;
};

}  // namespace cdcr::test_support
