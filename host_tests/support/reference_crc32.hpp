#pragma once
// CRC-32 computed one bit at a time straight from the polynomial, for tests
// that build or check image trailers with something that shares no code with
// the table-driven implementation.

#include <cstddef>
#include <cstdint>

namespace cdcr::test_support {

inline std::uint32_t reference_crc32(const std::uint8_t* data, std::size_t size) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) {
    crc ^= data[i];
    for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ ((crc & 1u) != 0 ? 0xEDB88320u : 0u);
  }
  return ~crc;
}

}  // namespace cdcr::test_support
