#include "view/view_session.hpp"

#include <chrono>

#include "view/foxglove_server.hpp"
#include "view/view_recording.hpp"

namespace cdcr::view {

ViewSession::ViewSession(const std::vector<std::uint8_t>& image, const ViewOptions& options,
                         const ViewOutputs& outputs)
    : record_path_(outputs.record_path) {
  if (outputs.port >= 0) {
    server_ = std::make_unique<FoxgloveServer>(static_cast<std::uint16_t>(outputs.port), outputs.server_name);
    sinks_.add(server_.get());
  }
  if (!outputs.record_path.empty()) {
    recording_ = std::make_unique<ViewRecording>(outputs.record_path);
    sinks_.add(recording_.get());
  }
  view_ = std::make_unique<RobotView>(image, options, sinks_);
}

ViewSession::~ViewSession() = default;

std::uint16_t ViewSession::port() const { return server_ ? server_->port() : 0; }

void ViewSession::close_recording() {
  if (recording_) recording_->close();
}

std::uint64_t ViewSession::recorded_messages() const { return recording_ ? recording_->message_count() : 0; }

std::string ViewSession::recording_report() const {
  if (!recording_) return {};
  return "recording: " + record_path_ + ", " + std::to_string(recording_->message_count()) +
         " messages (MCAP; open it in Foxglove, Lichtblick or PlotJuggler)";
}

std::uint64_t wall_clock_ns() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count());
}

}  // namespace cdcr::view
