#pragma once
// The robot as a listener on its bus sees it: every frame decoded with the
// protocol's one codec, the shape rebuilt from the cable feedback with the
// image's model, and the view's channels (view_channels.hpp) published to a
// sink as JSON messages stamped with the frame's time.
//
// - The backbone: each segment's nominal arc (constant curvature, the
//   bend the model reads from its cables), sampled along its length.
// - The tip: the compensated pose of the same cables, as the runtime's
//   forward path computes it (with the image's hysteresis block, the cables
//   tracked as the board tracks them, homed by the HOMING frame), its r95
//   radii and extrapolation flag; red when extrapolating.
// - The target (the latest committed TARGET), the setpoints (CABLE_SETPOINT,
//   CABLE_SETPOINTS_FD) and the following error, STATUS and IK_REPORT.
//
// Each complete set of cable feedback (the last segment's frame) publishes
// the tip and the cables; the scene and frames go out at most at
// scene_rate_hz of frame time. The view never sends a frame.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <cdcr/firmware/kinematics.hpp>
#include <cdcr/firmware/protocol/message_codec.hpp>
#include <cdcr/hal/can_bus.hpp>

#include "view/view_channels.hpp"

namespace cdcr::view {

class ViewSink {
 public:
  virtual ~ViewSink() = default;
  virtual void publish(Topic topic, std::uint64_t time_ns, const std::string& json) = 0;
};

struct ViewOptions {
  double scene_rate_hz = 30;
  // Where the protocol's identifiers are on this bus (messages.hpp id_offset).
  std::uint32_t id_offset = 0;
  int points_per_segment = 16;
};

class RobotView {
 public:
  // Throws std::runtime_error (one line) for an image the runtime would not
  // run compensated or nominal.
  RobotView(const std::vector<std::uint8_t>& image, const ViewOptions& options, ViewSink& sink);
  ~RobotView();

  void on_frame(const hal::CanFrame& frame, std::uint64_t time_ns);

  long frames() const { return frames_; }
  // Frames at the protocol's identifiers that did not decode.
  long malformed_frames() const { return malformed_; }
  long scenes() const { return scenes_; }
  int segment_count() const;
  // Empty, or why the image's model is not the one shown (one line).
  const std::string& note() const { return note_; }

 private:
  struct State;
  // Each takes the frame if it is one of its messages (true).
  bool take_cables(const hal::CanFrame& frame, std::uint64_t time_ns);
  bool take_target(const hal::CanFrame& frame, std::uint64_t time_ns);
  void take_report(const hal::CanFrame& frame, std::uint64_t time_ns);
  bool take_segment(const double* lengths_mm, int segment, firmware::Cables& into) const;
  // Counts a frame at a message's identifier that does not decode.
  bool decoded(firmware::protocol::DecodeStatus status);
  void on_feedback_complete(std::uint64_t time_ns);
  void publish_scene(std::uint64_t time_ns);

  std::unique_ptr<State> state_;
  ViewOptions options_;
  ViewSink& sink_;
  long frames_ = 0, malformed_ = 0, scenes_ = 0;
  std::string note_;
};

// The sinks a view feeds at once (the live server and a recording).
class SinkList final : public ViewSink {
 public:
  void add(ViewSink* sink) {
    if (sink != nullptr) sinks_.push_back(sink);
  }
  void publish(Topic topic, std::uint64_t time_ns, const std::string& json) override {
    for (ViewSink* sink : sinks_) sink->publish(topic, time_ns, json);
  }
  bool empty() const { return sinks_.empty(); }

 private:
  std::vector<ViewSink*> sinks_;
};

}  // namespace cdcr::view
