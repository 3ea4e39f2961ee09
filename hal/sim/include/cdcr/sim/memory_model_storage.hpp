#pragma once
// The simulated board's model region: an image held in memory (a file read
// into a buffer), aligned as a flash section is.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

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

}  // namespace cdcr::sim
