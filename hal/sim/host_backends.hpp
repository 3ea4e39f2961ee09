#pragma once
// Host stand-ins for the remaining HAL interfaces: a model region backed by
// memory (an image file read into a buffer) and a console on stderr.

#include <cstdint>
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <cdcr/hal/console.hpp>
#include <cdcr/hal/model_storage.hpp>

namespace cdcr::sim {

class MemoryModelStorage final : public hal::ModelStorage {
 public:
  MemoryModelStorage() = default;
  // The bytes are copied into 8-byte-aligned storage, as a flash section is.
  explicit MemoryModelStorage(const std::vector<std::uint8_t>& bytes) { assign(bytes); }

  void assign(const std::vector<std::uint8_t>& bytes) {
    words_.assign((bytes.size() + 7) / 8, 0);
    if (!bytes.empty()) std::copy(bytes.begin(), bytes.end(), reinterpret_cast<std::uint8_t*>(words_.data()));
    size_bytes_ = bytes.size();
  }

  hal::MemoryRegion model_region() const override {
    if (size_bytes_ == 0) return {};
    return {reinterpret_cast<const std::uint8_t*>(words_.data()), size_bytes_};
  }

 private:
  std::vector<std::uint64_t> words_;
  std::size_t size_bytes_ = 0;
};

class StderrConsole final : public hal::Console {
 public:
  explicit StderrConsole(bool enabled = true) : enabled_(enabled) {}
  void write_line(const char* line) override {
    if (enabled_) std::fprintf(stderr, "%s\n", line);
  }

 private:
  bool enabled_;
};

// Keeps the lines for tests to inspect (host only: it allocates).
class RecordingConsole final : public hal::Console {
 public:
  void write_line(const char* line) override { lines.emplace_back(line); }
  std::vector<std::string> lines;
};

}  // namespace cdcr::sim
