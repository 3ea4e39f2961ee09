#pragma once
// The CAN FD messages (messages.hpp, "CAN FD messages") as typed frames:
// each is its parts' classical typed frames (frames.hpp), encoded and
// decoded by their own codecs and placed 8 bytes apart, so an FD frame
// holds exactly the bits its classical frames would.
//
//   protocol::PoseFd pose{xy, z, orientation, radii};
//   hal::CanFrame frame;
//   protocol::encode(pose, frame);          // one 32-byte FD frame
//   if (protocol::decode(frame, pose) == protocol::DecodeStatus::ok) { ... }

#include <cmath>
#include <limits>

#include "cdcr/firmware/protocol/frames.hpp"
#include "cdcr/firmware/protocol/message_codec.hpp"
#include "cdcr/firmware/protocol/messages.hpp"
#include "cdcr/hal/can_bus.hpp"

namespace cdcr::firmware::protocol {

// POSE_FD. position_z.radii says whether `uncertainty` holds radii; without
// them the part is sent as 0.
struct PoseFd {
  PosePositionXy position_xy;
  PosePositionZ position_z;
  PoseOrientation orientation;
  PoseUncertainty uncertainty;
};

// TARGET_FD: a committed target.
struct TargetFd {
  TargetOrientation orientation;
  TargetPositionXy position_xy;
  TargetPositionZ position_z;
};

// CABLE_SETPOINTS_FD_<index>: segments 4 index .. 4 index + 3, of which the
// first `segment_count` are the robot's (the others go as not available).
struct CableSetpointsFd {
  int index = 0;
  int segment_count = 0;
  CableSetpoint segments[cable_setpoints_fd::kSegmentsPerFrame];
};

namespace detail {

template <typename Part>
void place(const Part& part, int k, hal::CanFrame& frame) {
  hal::CanFrame classical;
  encode(part, classical);
  put_part(frame, k, classical);
}

}  // namespace detail

// Part k of an FD frame of `message` decoded as its classical typed frame;
// the frame's own checks (check_fd_frame) first.
template <typename Part>
DecodeStatus decode_part(const FdMessageSpec& message, const hal::CanFrame& frame, int part, Part& f) {
  if (const DecodeStatus s = check_fd_frame(message, frame); s != DecodeStatus::ok) return s;
  return decode(part_frame(message, frame, part, static_cast<int>(frame.id - message.id)), f);
}

inline void encode(const PoseFd& f, hal::CanFrame& frame) {
  frame = empty_frame(pose_fd::kMessage);
  detail::place(f.position_xy, 0, frame);
  detail::place(f.position_z, 1, frame);
  detail::place(f.orientation, 2, frame);
  if (f.position_z.radii) detail::place(f.uncertainty, 3, frame);
}

inline DecodeStatus decode(const hal::CanFrame& frame, PoseFd& f) {
  PoseFd out;
  DecodeStatus s = decode_part(pose_fd::kMessage, frame, 0, out.position_xy);
  if (s == DecodeStatus::ok) s = decode_part(pose_fd::kMessage, frame, 1, out.position_z);
  if (s == DecodeStatus::ok) s = decode_part(pose_fd::kMessage, frame, 2, out.orientation);
  if (s == DecodeStatus::ok) s = decode_part(pose_fd::kMessage, frame, 3, out.uncertainty);
  if (s == DecodeStatus::ok) f = out;
  return s;
}

inline void encode(const TargetFd& f, hal::CanFrame& frame) {
  frame = empty_frame(target_fd::kMessage);
  detail::place(f.orientation, 0, frame);
  detail::place(f.position_xy, 1, frame);
  detail::place(f.position_z, 2, frame);
}

inline DecodeStatus decode(const hal::CanFrame& frame, TargetFd& f) {
  TargetFd out;
  DecodeStatus s = decode_part(target_fd::kMessage, frame, 0, out.orientation);
  if (s == DecodeStatus::ok) s = decode_part(target_fd::kMessage, frame, 1, out.position_xy);
  if (s == DecodeStatus::ok) s = decode_part(target_fd::kMessage, frame, 2, out.position_z);
  if (s == DecodeStatus::ok) f = out;
  return s;
}

// False, and the frame untouched, when a length is refused (as CABLE_SETPOINT's encoder).
inline bool encode(const CableSetpointsFd& f, hal::CanFrame& frame) {
  const FdMessageSpec& message = cable_setpoints_fd::kMessage;
  if (f.index < 0 || f.index >= message.id_count || f.segment_count < 0 ||
      f.segment_count > cable_setpoints_fd::kSegmentsPerFrame) {
    return false;
  }
  hal::CanFrame out = empty_frame(message, f.index);
  for (int k = 0; k < message.part_count; ++k) {
    CableSetpoint setpoint;
    if (k < f.segment_count) {
      setpoint = f.segments[k];
    } else {
      for (double& length : setpoint.lengths_mm) length = std::numeric_limits<double>::quiet_NaN();
    }
    setpoint.segment = message.part_segment(k, f.index);
    hal::CanFrame classical;
    if (k < f.segment_count) {
      if (!encode(setpoint, classical)) return false;
    } else {
      // Not the robot's: every length not available (the encoder sends only the last one so).
      classical = empty_frame(cable_setpoint::kMessage, setpoint.segment);
      for (const SignalSpec* signal : cable_setpoint::kMessage.signals) write_raw(classical, *signal, kCableNotAvailableRaw);
    }
    put_part(out, k, classical);
  }
  frame = out;
  return true;
}

// The robot's segments of a CABLE_SETPOINTS_FD frame: the parts before
// the first whose every length is not available.
inline DecodeStatus decode(const hal::CanFrame& frame, CableSetpointsFd& f) {
  const FdMessageSpec& message = cable_setpoints_fd::kMessage;
  CableSetpointsFd out;
  out.index = static_cast<int>(frame.id - message.id);
  bool ended = false;
  if (const DecodeStatus s = check_fd_frame(message, frame); s != DecodeStatus::ok) return s;
  for (int k = 0; k < message.part_count; ++k) {
    const hal::CanFrame part = part_frame(message, frame, k, out.index);
    bool absent = true;
    for (const SignalSpec* signal : cable_setpoint::kMessage.signals) {
      absent = absent && read_raw(part, *signal) == kCableNotAvailableRaw;
    }
    if (absent) {
      ended = true;
      continue;
    }
    if (ended) return DecodeStatus::out_of_range;  // a segment after one the robot lacks
    if (const DecodeStatus s = decode(part, out.segments[out.segment_count]); s != DecodeStatus::ok) return s;
    ++out.segment_count;
  }
  f = out;
  return DecodeStatus::ok;
}

}  // namespace cdcr::firmware::protocol
