#pragma once
// Loading a flash image for a command: the bytes, kept alive alongside the
// validated zero-copy view into them.

#include <cstdint>
#include <string>
#include <vector>

#include "cdcr/model/flash_image.hpp"

namespace cdcr::cli {

struct LoadedImage {
  std::vector<std::uint8_t> bytes;
  model::ImageView view{};
};

// Throws InputError naming the file and the parser's status.
LoadedImage load_image(const std::string& path);

}  // namespace cdcr::cli
