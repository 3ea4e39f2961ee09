#pragma once
// Whole-file byte I/O for images and their exported forms.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace cdcr::exporting {

// Throws std::runtime_error naming the path if the file cannot be read.
std::vector<std::uint8_t> read_binary_file(const std::string& path);

// Writes to a temporary file next to `path` and renames it over `path`, so
// a failed export never leaves a half-written image behind. Throws
// std::runtime_error naming the path.
void write_binary_file(const std::string& path, const void* data, std::size_t size);

}  // namespace cdcr::exporting
