#pragma once
// The runtime's CAN protocol, as one codec in protocol/:
//
//   signal_codec.hpp   a DBC signal (Intel byte order, any start bit, 1..32
//                      bits, scale, offset, range) and how it is read and written
//   message_codec.hpp  a DBC message and the checks before decoding one
//   messages.hpp       the table: every message and signal, the enums' value
//                      tables, the acceptance filter of each frame group
//   frames.hpp         one typed struct per message, with encode() and decode()
//
// firmware/protocol/cdcr.dbc describes the same frames for candump/cantools
// users, and a host test checks that both agree field by field.
//
//   id           name                 dlc  sender   content
//   0x100+s      CABLE_FEEDBACK_s     8    drives   segment s's 4 cable lengths, u16 x 0.01 mm
//   0x110+s      CABLE_SETPOINT_s     8    runtime  segment s's 4 commanded cable lengths, u16 x 0.01 mm
//   0x120        TARGET_ORIENTATION   8    host     target quaternion, i16 Q15 (before the commit frame)
//   0x121        TARGET_POSITION_XY   8    host     target x, y, i32 x 0.01 mm
//   0x122        TARGET_POSITION_Z    6    host     target z, mode, tracking, sequence: commits the target
//   0x130        POSE_POSITION_XY     8    runtime  tip x, y, i32 x 0.01 mm
//   0x131        POSE_POSITION_Z      6    runtime  tip z, flags, sequence
//   0x132        POSE_ORIENTATION     8    runtime  tip quaternion, i16 Q15
//   0x140        IK_REPORT            8    runtime  outcome of a target: iterations, cycles, residuals
//   0x150        STATUS               8    runtime  heartbeat: state, fault, overruns, execution time
//   0x151        STATS                8    runtime  jitter, rejected frames, cycle counter, fault detail

#include "cdcr/firmware/protocol/frames.hpp"
#include "cdcr/firmware/protocol/message_codec.hpp"
#include "cdcr/firmware/protocol/messages.hpp"
#include "cdcr/firmware/protocol/signal_codec.hpp"
