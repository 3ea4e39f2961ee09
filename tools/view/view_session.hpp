#pragma once
// A view with where it goes: served live (a port), recorded (a path), or
// both. What `cdcr view`, `cdcr-runtime --sim` and `--replay` each set up.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "view/robot_view.hpp"

namespace cdcr::view {

class FoxgloveServer;
class ViewRecording;

struct ViewOutputs {
  int port = -1;             // -1: not served; 0: any free port
  std::string record_path;   // empty: not recorded
  std::string server_name;   // what the server tells its clients
};

class ViewSession {
 public:
  // Throws std::runtime_error (one line) when the server cannot listen, the
  // recording cannot be written or the image cannot be used.
  ViewSession(const std::vector<std::uint8_t>& image, const ViewOptions& options, const ViewOutputs& outputs);
  ~ViewSession();
  ViewSession(const ViewSession&) = delete;
  ViewSession& operator=(const ViewSession&) = delete;

  RobotView& view() { return *view_; }
  const RobotView& view() const { return *view_; }
  bool served() const { return server_ != nullptr; }
  std::uint16_t port() const;  // of a served view
  // Closes the recording, if there is one (renamed into place).
  void close_recording();
  std::uint64_t recorded_messages() const;
  // "recording: PATH, N messages (...)"; empty without a recording.
  std::string recording_report() const;

 private:
  SinkList sinks_;
  std::unique_ptr<FoxgloveServer> server_;
  std::unique_ptr<ViewRecording> recording_;
  std::unique_ptr<RobotView> view_;
  std::string record_path_;
};

// The wall clock in ns since the epoch: the stamp of what a view sees.
std::uint64_t wall_clock_ns();

}  // namespace cdcr::view
