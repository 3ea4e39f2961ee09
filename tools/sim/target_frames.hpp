#pragma once
// The frames a host sends the runtime for one target, in the order it must
// send them: TARGET_ORIENTATION (pose targets only), TARGET_POSITION_XY, then
// TARGET_POSITION_Z, which commits the target; on a CAN FD bus one
// TARGET_FD instead.

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include <cdcr/firmware/protocol/fd_frames.hpp>
#include <cdcr/firmware/protocol/frames.hpp>
#include <cdcr/hal/can_bus.hpp>
#include <cdcr/model/se3.hpp>

namespace cdcr::sim {

// tracking: the target is one of a stream along a path (TRACKING = 1).
inline std::vector<hal::CanFrame> target_frames(const model::Vec3<double>& position_mm,
                                                firmware::protocol::TargetMode mode, bool tracking,
                                                std::uint8_t sequence) {
  namespace protocol = firmware::protocol;
  std::vector<hal::CanFrame> frames(2);
  protocol::encode(protocol::TargetPositionXy{position_mm.x(), position_mm.y()}, frames[0]);
  protocol::encode(protocol::TargetPositionZ{position_mm.z(), mode, tracking, sequence}, frames[1]);
  return frames;
}

// A pose target's rotation goes as a unit quaternion; a position target
// (TargetMode::position) sends none.
inline std::vector<hal::CanFrame> target_frames(const model::Pose<double>& target, firmware::protocol::TargetMode mode,
                                                bool tracking, std::uint8_t sequence) {
  namespace protocol = firmware::protocol;
  std::vector<hal::CanFrame> frames;
  if (mode == protocol::TargetMode::pose) {
    Eigen::Quaterniond q(target.rotation);
    q.normalize();
    frames.emplace_back();
    protocol::encode(protocol::TargetOrientation{q.w(), q.x(), q.y(), q.z()}, frames.back());
  }
  for (const hal::CanFrame& frame : target_frames(target.position_mm, mode, tracking, sequence)) {
    frames.push_back(frame);
  }
  return frames;
}

// The same target in one TARGET_FD frame, for a CAN FD bus: the parts the
// classical frames carry (a position target's orientation part is 0).
inline hal::CanFrame target_fd_frame(const model::Pose<double>& target, firmware::protocol::TargetMode mode,
                                     bool tracking, std::uint8_t sequence) {
  namespace protocol = firmware::protocol;
  protocol::TargetFd message;
  if (mode == protocol::TargetMode::pose) {
    Eigen::Quaterniond q(target.rotation);
    q.normalize();
    message.orientation = {q.w(), q.x(), q.y(), q.z()};
  } else {
    message.orientation = {0, 0, 0, 0};
  }
  message.position_xy = {target.position_mm.x(), target.position_mm.y()};
  message.position_z = {target.position_mm.z(), mode, tracking, sequence};
  hal::CanFrame frame;
  protocol::encode(message, frame);
  return frame;
}

}  // namespace cdcr::sim
