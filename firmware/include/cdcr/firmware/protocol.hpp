#pragma once
// The runtime's CAN protocol, as one codec in protocol/:
//
//   signal_codec.hpp   a DBC signal (Intel byte order, any start bit, 1..32
//                      bits, scale, offset, range) and how it is read and written
//   message_codec.hpp  a DBC message and the checks before decoding one
//   messages.hpp       the table: every message and signal, the enums' value
//                      tables, the acceptance filter of each frame group, the
//                      DBC file's receivers and comments
//   frames.hpp         one typed struct per message, with encode() and decode()
//
// The table is the protocol's one description. The build writes the DBC
// file for candump/cantools users from it (firmware/protocol/write_dbc.cpp,
// into <build>/firmware/protocol/cdcr.dbc); a host test reads that file back
// with a parser of its own, and golden frames written by hand
// (host_tests/firmware/protocol_golden_frames_test.cpp) pin every message's
// bytes.
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
//   0x133        POSE_UNCERTAINTY     7    runtime  95 % radii, latent variance share, flags, the pose's sequence
//   0x140        IK_REPORT            8    runtime  outcome of a target: iterations, cycles, residuals
//   0x150        STATUS               8    runtime  heartbeat: state, fault, overruns, execution time
//   0x151        STATS                8    runtime  jitter, rejected frames, cycle counter, fault detail
//   0x160        PAYLOAD              2    host     tip payload, u16 x 0.001 kg
//   0x170        UPDATE_COMMAND       6    host     model update: start, status, abort, commit, rollback
//   0x171        UPDATE_DIGEST        5    host     4 bytes of the image's SHA-256
//   0x172        UPDATE_BLOCK         7    host     block header: number, length, CRC-32
//   0x173        UPDATE_DATA          8    host     the block's next 8 bytes
//   0x178        UPDATE_REPORT        8    runtime  the update's state, acknowledged blocks, window

#include "cdcr/firmware/protocol/frames.hpp"
#include "cdcr/firmware/protocol/message_codec.hpp"
#include "cdcr/firmware/protocol/messages.hpp"
#include "cdcr/firmware/protocol/signal_codec.hpp"
