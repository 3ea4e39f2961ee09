#pragma once
// The bus's inputs to the runtime: cable feedback, the three frames of a
// target (or its one TARGET_FD frame), the payload. Each is decoded and handed to the runtime's direct
// calls (Runtime::set_*), which callers without a bus use as they are; a
// frame that does not decode is rejected with its fault code.

#include "cdcr/firmware/protocol.hpp"
#include "cdcr/hal/can_bus.hpp"

namespace cdcr::firmware {

class Runtime;

class FrameInputs {
 public:
  // False for a frame that is not an input (another node's, or the model
  // update's).
  bool take(const hal::CanFrame& frame, Runtime& runtime);
  // A target committed another way ends the one in parts: its commit would
  // find no parts, as after any commit.
  void drop_parts() { has_pending_position_ = has_pending_orientation_ = false; }

 private:
  void take_commit(const hal::CanFrame& frame, Runtime& runtime);
  void take_fd_target(const hal::CanFrame& frame, Runtime& runtime);

  // The parts of a target received before its commit frame.
  bool has_pending_position_ = false;
  bool has_pending_orientation_ = false;
  protocol::TargetPositionXy pending_position_;
  protocol::TargetOrientation pending_orientation_;
};

}  // namespace cdcr::firmware
