#include "image_input.hpp"

#include <fstream>
#include <iterator>

#include <fmt/format.h>

#include "cli_errors.hpp"

namespace cdcr::cli {

LoadedImage load_image(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(fmt::format("{}: cannot open file", path));
  LoadedImage image;
  image.bytes.assign(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
  const model::ImageStatus status = model::parse_image(image.bytes.data(), image.bytes.size(), image.view);
  if (status != model::ImageStatus::ok) throw InputError(fmt::format("{}: {}", path, model::to_string(status)));
  return image;
}

}  // namespace cdcr::cli
