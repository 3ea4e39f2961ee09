#pragma once
// The view's channels recorded to an MCAP file (mcap_writer.hpp): one
// channel per topic with its JSON schema, every message as published.

#include <array>
#include <cstdint>
#include <string>

#include "view/mcap_writer.hpp"
#include "view/robot_view.hpp"

namespace cdcr::view {

class ViewRecording final : public ViewSink {
 public:
  explicit ViewRecording(const std::string& path);
  void publish(Topic topic, std::uint64_t time_ns, const std::string& json) override;
  // Closes the file and renames it into place (mcap_writer.hpp).
  void close() { writer_.close(); }
  std::uint64_t message_count() const { return writer_.message_count(); }

 private:
  McapWriter writer_;
  std::array<std::uint16_t, kTopicCount> channel_ids_{};
};

}  // namespace cdcr::view
