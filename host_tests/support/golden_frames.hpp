#pragma once
// Golden frames written out by hand: a frame from its identifier and bytes,
// and its text ("0x185 [37 02 06 FF FF FF]") for a failure to name it.

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <cdcr/hal/can_bus.hpp>

namespace cdcr::test_support {

using Bytes = std::vector<std::uint8_t>;

inline hal::CanFrame frame_of(std::uint32_t id, const Bytes& bytes) {
  hal::CanFrame frame;
  frame.id = id;
  frame.dlc = static_cast<std::uint8_t>(bytes.size());
  std::copy(bytes.begin(), bytes.end(), frame.data);
  return frame;
}

inline std::string frame_text(const hal::CanFrame& frame) {
  char buffer[8];
  std::snprintf(buffer, sizeof buffer, "0x%03X", unsigned(frame.id));
  std::string text = std::string(buffer) + " [";
  for (int i = 0; i < frame.dlc; ++i) {
    std::snprintf(buffer, sizeof buffer, i ? " %02X" : "%02X", frame.data[i]);
    text += buffer;
  }
  return text + "]";
}

}  // namespace cdcr::test_support
