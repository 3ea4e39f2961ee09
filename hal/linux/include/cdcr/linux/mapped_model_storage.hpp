#pragma once
// The model region on a Linux host: the image file mapped read-only, so the
// runtime parses it in place exactly as it does a flash section.

#include <cstddef>
#include <cstdint>
#include <string>

#include <cdcr/hal/model_storage.hpp>

namespace cdcr::linux_host {

class MappedModelStorage final : public hal::ModelStorage {
 public:
  MappedModelStorage() = default;
  ~MappedModelStorage();
  MappedModelStorage(const MappedModelStorage&) = delete;
  MappedModelStorage& operator=(const MappedModelStorage&) = delete;

  // An empty file maps to an empty region (no image). On failure returns
  // false, keeps no mapping and describes the cause in `error`.
  bool map_file(const std::string& path, std::string& error);
  void unmap();

  hal::MemoryRegion model_region() const override { return {bytes_, size_bytes_}; }

 private:
  const std::uint8_t* bytes_ = nullptr;
  std::size_t size_bytes_ = 0;
};

}  // namespace cdcr::linux_host
