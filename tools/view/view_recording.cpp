#include "view/view_recording.hpp"

namespace cdcr::view {

ViewRecording::ViewRecording(const std::string& path) : writer_(path) {
  // Topics of one schema share it.
  std::array<std::uint16_t, kTopicCount> schema_ids{};
  for (int t = 0; t < kTopicCount; ++t) {
    const ChannelDescription& c = view_channels()[t];
    std::uint16_t schema_id = 0;
    for (int u = 0; u < t && schema_id == 0; ++u) {
      if (std::string(view_channels()[u].schema_name) == c.schema_name) schema_id = schema_ids[u];
    }
    if (schema_id == 0) schema_id = writer_.add_schema(c.schema_name, "jsonschema", c.schema);
    schema_ids[t] = schema_id;
    channel_ids_[t] = writer_.add_channel(schema_id, c.topic, "json");
  }
}

void ViewRecording::publish(Topic topic, std::uint64_t time_ns, const std::string& json) {
  writer_.write_message(channel_ids_[static_cast<int>(topic)], time_ns, json);
}

}  // namespace cdcr::view
