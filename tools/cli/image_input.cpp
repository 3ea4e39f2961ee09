#include "image_input.hpp"

#include <fmt/format.h>

#include "cli_errors.hpp"
#include "export/binary_file.hpp"

namespace cdcr::cli {

LoadedImage load_image(const std::string& path) {
  LoadedImage image;
  try {
    image.bytes = exporting::read_binary_file(path);
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
  const model::ImageStatus status = model::parse_image(image.bytes.data(), image.bytes.size(), image.view);
  if (status != model::ImageStatus::ok) throw InputError(fmt::format("{}: {}", path, model::to_string(status)));
  return image;
}

}  // namespace cdcr::cli
