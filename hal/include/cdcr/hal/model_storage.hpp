#pragma once
// Read access to the region that holds the model image: on a board a flash
// section the runtime parses in place, on the host a file loaded into memory.

#include <cstddef>
#include <cstdint>

#include "cdcr/hal/interface.hpp"

namespace cdcr::hal {

struct MemoryRegion {
  const std::uint8_t* data = nullptr;  // nullptr: no region (nothing flashed)
  std::size_t size_bytes = 0;
};

class ModelStorage : public Interface {
 public:
  virtual MemoryRegion model_region() const = 0;

 protected:
  ~ModelStorage() = default;
};

}  // namespace cdcr::hal
