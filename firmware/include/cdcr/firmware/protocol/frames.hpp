#pragma once
// The protocol's messages as typed frames: one struct per message, its fields
// named after the DBC signals, encoded and decoded through the signal table
// of messages.hpp, so each signal's bits are written down once.
//
//   hal::CanFrame frame;
//   protocol::encode(protocol::TargetPositionZ{z_mm, protocol::TargetMode::pose, false, 7}, frame);
//   protocol::TargetPositionZ target;
//   if (protocol::decode(frame, target) == protocol::DecodeStatus::ok) { ... }
//
// Encoders saturate what a signal cannot hold (counters, residuals), except
// cable lengths, which they refuse (a clipped cable length is a wrong one):
// those encoders return false and leave the frame alone. Decoders check the
// identifier, the DLC, the reserved bits and every signal's range first, and
// write the struct only when the frame is well formed.

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <limits>
#include <type_traits>

#include "cdcr/firmware/fault.hpp"
#include "cdcr/firmware/fault_detail.hpp"
#include "cdcr/firmware/protocol/message_codec.hpp"
#include "cdcr/firmware/protocol/messages.hpp"
#include "cdcr/firmware/protocol/signal_codec.hpp"
#include "cdcr/hal/can_bus.hpp"
#include "cdcr/model/crc32.hpp"

namespace cdcr::firmware::protocol {

// CABLE_FEEDBACK_s and CABLE_SETPOINT_s: the four cable lengths of a segment.
struct CableFeedback {
  int segment = 0;
  double lengths_mm[4] = {};  // L1..L4
};
struct CableSetpoint {
  int segment = 0;
  double lengths_mm[4] = {};  // L1..L4
};

// PAYLOAD: kg.
// The homing move has ended: the robot is at home (HOMING).
struct Homing {
  bool at_home = true;
};

struct Payload {
  double payload_kg = 0;
};

struct TargetOrientation {
  double qw = 1, qx = 0, qy = 0, qz = 0;
};
struct TargetPositionXy {
  double x_mm = 0, y_mm = 0;
};
struct TargetPositionZ {
  double z_mm = 0;
  TargetMode mode = TargetMode::position;
  bool tracking = false;
  std::uint8_t sequence = 0;
  bool refuse_extrapolating = false;
};

struct PosePositionXy {
  double x_mm = 0, y_mm = 0;
};
struct PosePositionZ {
  double z_mm = 0;
  bool compensated = false;    // FLAGS bit 0
  std::uint8_t sequence = 0;
  bool extrapolating = false;  // FLAGS bit 1
};
struct PoseUncertainty {
  double r95_position_mm = 0;     // saturates at 65.535 mm
  double r95_orientation_deg = 0; // saturates at 65.535 deg
  double latent_share = 0;        // 0..1
  bool extrapolating = false;
  bool outside_range = false;
  std::uint8_t sequence = 0;      // the pose's
};
struct PoseOrientation {
  double qw = 1, qx = 0, qy = 0, qz = 0;
};

struct IkReport {
  std::uint8_t sequence = 0;
  IkOutcome outcome = IkOutcome::converged;
  int iterations = 0;                   // saturates at 255
  int cycles = 0;                       // saturates at 255
  double position_residual_mm = 0;      // saturates at 65.535 mm; NaN and infinity encode as that
  double orientation_residual_rad = 0;  // saturates at 0.65535 rad, likewise
};

struct Status {
  RuntimeState state = RuntimeState::boot;
  FaultCode fault = FaultCode::none;
  std::int64_t overruns = 0;  // the u16 counters saturate
  std::int64_t exec_max_us = 0;
  std::int64_t exec_mean_us = 0;
  bool extrapolating = false;  // the latest pose's (POSE_POSITION_Z FLAGS bit 1)
  bool hysteresis_unknown = false;  // the cables' hysteresis state is not yet known
};

struct Stats {
  std::int64_t jitter_max_us = 0;  // saturates, as the other counters
  std::int64_t rejected_frames = 0;
  std::uint16_t cycle_count = 0;  // wraps
  FaultDetail fault_detail;        // of the FAULT in the STATUS frame sent with it
  std::int64_t stale_events = 0;
};

// A cable length's raw value, if it survives the frame: positive after
// rounding to the 0.01 mm quantum and short of the "not available" mark
// (655.34 mm at most). Scaled once, in single precision where that gives the
// double result (a core without a double-precision FPU pays for each).
inline bool cable_length_raw(const SignalSpec& signal, double length_mm, std::int64_t& raw) {
  return to_raw_checked_single(signal, length_mm, raw) && raw != 0 && raw != kCableNotAvailableRaw;
}

inline bool cable_length_encodable(double length_mm) {
  std::int64_t raw = 0;
  return cable_length_raw(cable_lengths::kL1, length_mm, raw);
}

// The length a receiver decodes for `length_mm` (which must be encodable).
inline double cable_length_as_transmitted(double length_mm) { return as_transmitted(cable_lengths::kL1, length_mm); }

namespace cable_frames {

inline bool encode(const MessageSpec& message, int segment, const double (&lengths_mm)[4], hal::CanFrame& frame) {
  if (segment < 0 || segment >= message.id_count) return false;
  std::uint64_t word = 0;
  int k = 0;
  for (const SignalSpec* signal : message.signals) {
    std::int64_t raw = 0;
    if (!cable_length_raw(*signal, lengths_mm[k++], raw)) return false;
    word |= placed(*signal, raw);
  }
  frame = empty_frame(message, segment);
  set_data_word(frame, word);
  return true;
}

inline DecodeStatus decode(const MessageSpec& message, const hal::CanFrame& frame, int& segment,
                           double (&lengths_mm)[4]) {
  if (const DecodeStatus s = check_frame(message, frame); s != DecodeStatus::ok) return s;
  const std::uint64_t word = data_word(frame);
  double decoded_mm[4];
  int k = 0;
  for (const SignalSpec* signal : message.signals) {
    const std::int64_t raw = raw_in_word(word, *signal);
    if (raw == kCableNotAvailableRaw) return DecodeStatus::not_available;
    if (raw == 0) return DecodeStatus::out_of_range;  // a cable has a length
    decoded_mm[k++] = to_physical(*signal, raw);
  }
  segment = static_cast<int>(frame.id - message.id);
  for (int i = 0; i < 4; ++i) lengths_mm[i] = decoded_mm[i];
  return DecodeStatus::ok;
}

}  // namespace cable_frames

inline bool encode(const CableFeedback& f, hal::CanFrame& frame) {
  return cable_frames::encode(cable_feedback::kMessage, f.segment, f.lengths_mm, frame);
}
inline DecodeStatus decode(const hal::CanFrame& frame, CableFeedback& f) {
  return cable_frames::decode(cable_feedback::kMessage, frame, f.segment, f.lengths_mm);
}
inline bool encode(const CableSetpoint& f, hal::CanFrame& frame) {
  return cable_frames::encode(cable_setpoint::kMessage, f.segment, f.lengths_mm, frame);
}
inline DecodeStatus decode(const hal::CanFrame& frame, CableSetpoint& f) {
  return cable_frames::decode(cable_setpoint::kMessage, frame, f.segment, f.lengths_mm);
}

namespace quaternion_frames {

inline void encode(const MessageSpec& message, double qw, double qx, double qy, double qz, hal::CanFrame& frame) {
  frame = empty_frame(message);
  set_data_word(frame, placed_saturating(quaternion::kQw, qw) | placed_saturating(quaternion::kQx, qx) |
                           placed_saturating(quaternion::kQy, qy) | placed_saturating(quaternion::kQz, qz));
}

template <typename Frame>
DecodeStatus decode(const MessageSpec& message, const hal::CanFrame& frame, Frame& out) {
  if (const DecodeStatus s = check_frame(message, frame); s != DecodeStatus::ok) return s;
  const std::uint64_t word = data_word(frame);
  out.qw = physical_in_word(word, quaternion::kQw);
  out.qx = physical_in_word(word, quaternion::kQx);
  out.qy = physical_in_word(word, quaternion::kQy);
  out.qz = physical_in_word(word, quaternion::kQz);
  return DecodeStatus::ok;
}

}  // namespace quaternion_frames

namespace position_xy_frames {

inline void encode(const MessageSpec& message, double x_mm, double y_mm, hal::CanFrame& frame) {
  frame = empty_frame(message);
  set_data_word(frame, placed_saturating(position_xy::kX, x_mm) | placed_saturating(position_xy::kY, y_mm));
}

template <typename Frame>
DecodeStatus decode(const MessageSpec& message, const hal::CanFrame& frame, Frame& out) {
  if (const DecodeStatus s = check_frame(message, frame); s != DecodeStatus::ok) return s;
  const std::uint64_t word = data_word(frame);
  out.x_mm = physical_in_word(word, position_xy::kX);
  out.y_mm = physical_in_word(word, position_xy::kY);
  return DecodeStatus::ok;
}

}  // namespace position_xy_frames

inline void encode(const TargetOrientation& f, hal::CanFrame& frame) {
  quaternion_frames::encode(target_orientation::kMessage, f.qw, f.qx, f.qy, f.qz, frame);
}
inline DecodeStatus decode(const hal::CanFrame& frame, TargetOrientation& f) {
  return quaternion_frames::decode(target_orientation::kMessage, frame, f);
}
inline void encode(const PoseOrientation& f, hal::CanFrame& frame) {
  quaternion_frames::encode(pose_orientation::kMessage, f.qw, f.qx, f.qy, f.qz, frame);
}
inline DecodeStatus decode(const hal::CanFrame& frame, PoseOrientation& f) {
  return quaternion_frames::decode(pose_orientation::kMessage, frame, f);
}

inline void encode(const TargetPositionXy& f, hal::CanFrame& frame) {
  position_xy_frames::encode(target_position_xy::kMessage, f.x_mm, f.y_mm, frame);
}
inline DecodeStatus decode(const hal::CanFrame& frame, TargetPositionXy& f) {
  return position_xy_frames::decode(target_position_xy::kMessage, frame, f);
}
inline void encode(const PosePositionXy& f, hal::CanFrame& frame) {
  position_xy_frames::encode(pose_position_xy::kMessage, f.x_mm, f.y_mm, frame);
}
inline DecodeStatus decode(const hal::CanFrame& frame, PosePositionXy& f) {
  return position_xy_frames::decode(pose_position_xy::kMessage, frame, f);
}

inline void encode(const TargetPositionZ& f, hal::CanFrame& frame) {
  using namespace target_position_z;
  frame = empty_frame(kMessage);
  set_data_word(frame, placed_saturating(kZ, f.z_mm) | placed_integer(kMode, static_cast<std::int64_t>(f.mode)) |
                           placed_integer(kTracking, f.tracking ? 1 : 0) |
                           placed_integer(kRefuseExtrapolating, f.refuse_extrapolating ? 1 : 0) |
                           placed_integer(kSequence, f.sequence));
}
inline DecodeStatus decode(const hal::CanFrame& frame, TargetPositionZ& f) {
  using namespace target_position_z;
  if (const DecodeStatus s = check_frame(kMessage, frame); s != DecodeStatus::ok) return s;
  const std::uint64_t word = data_word(frame);
  f.z_mm = physical_in_word(word, kZ);
  f.mode = static_cast<TargetMode>(raw_in_word(word, kMode));
  f.tracking = raw_in_word(word, kTracking) != 0;
  f.refuse_extrapolating = raw_in_word(word, kRefuseExtrapolating) != 0;
  f.sequence = static_cast<std::uint8_t>(raw_in_word(word, kSequence));
  return DecodeStatus::ok;
}

// A payload outside the signal's range (or NaN) is refused: the encoder
// returns false and leaves the frame alone.
inline bool encode(const Payload& f, hal::CanFrame& frame) {
  std::int64_t raw = 0;
  if (!to_raw_checked(payload::kPayload, f.payload_kg, raw)) return false;
  frame = empty_frame(payload::kMessage);
  set_data_word(frame, placed(payload::kPayload, raw));
  return true;
}
inline DecodeStatus decode(const hal::CanFrame& frame, Payload& f) {
  if (const DecodeStatus s = check_frame(payload::kMessage, frame); s != DecodeStatus::ok) return s;
  f.payload_kg = physical_in_word(data_word(frame), payload::kPayload);
  return DecodeStatus::ok;
}

inline void encode(const Homing& f, hal::CanFrame& frame) {
  frame = empty_frame(homing::kMessage);
  set_data_word(frame, placed_integer(homing::kAtHome, f.at_home ? 1 : 0));
}
inline DecodeStatus decode(const hal::CanFrame& frame, Homing& f) {
  if (const DecodeStatus s = check_frame(homing::kMessage, frame); s != DecodeStatus::ok) return s;
  f.at_home = raw_in_word(data_word(frame), homing::kAtHome) != 0;
  return DecodeStatus::ok;
}

// The SEQUENCE of a TARGET_POSITION_Z frame that did not decode, so that
// the rejection can name its target; 0 when the frame is too short to hold one.
inline std::uint8_t commit_sequence(const hal::CanFrame& frame) {
  const SignalSpec& sequence = target_position_z::kSequence;
  if (8 * frame.dlc < sequence.start_bit + sequence.length_bits) return 0;
  return static_cast<std::uint8_t>(read_raw(frame, sequence));
}

inline void encode(const PosePositionZ& f, hal::CanFrame& frame) {
  using namespace pose_position_z;
  frame = empty_frame(kMessage);
  set_data_word(frame, placed_saturating(kZ, f.z_mm) |
                           placed_integer(kFlags, (f.compensated ? kFlagCompensated : 0) |
                                                      (f.extrapolating ? kFlagExtrapolating : 0)) |
                           placed_integer(kSequence, f.sequence));
}
inline DecodeStatus decode(const hal::CanFrame& frame, PosePositionZ& f) {
  using namespace pose_position_z;
  if (const DecodeStatus s = check_frame(kMessage, frame); s != DecodeStatus::ok) return s;
  const std::uint64_t word = data_word(frame);
  const std::int64_t flags = raw_in_word(word, kFlags);
  if ((flags & ~(kFlagCompensated | kFlagExtrapolating)) != 0) return DecodeStatus::reserved_bits_set;
  f.z_mm = physical_in_word(word, kZ);
  f.compensated = (flags & kFlagCompensated) != 0;
  f.extrapolating = (flags & kFlagExtrapolating) != 0;
  f.sequence = static_cast<std::uint8_t>(raw_in_word(word, kSequence));
  return DecodeStatus::ok;
}

inline void encode(const PoseUncertainty& f, hal::CanFrame& frame) {
  using namespace pose_uncertainty;
  frame = empty_frame(kMessage);
  set_data_word(frame, placed_saturating(kR95Position, f.r95_position_mm) |
                           placed_saturating(kR95Orientation, f.r95_orientation_deg) |
                           placed_saturating(kLatentShare, f.latent_share) |
                           placed_integer(kFlags, (f.extrapolating ? kFlagExtrapolating : 0) |
                                                      (f.outside_range ? kFlagOutsideRange : 0)) |
                           placed_integer(kSequence, f.sequence));
}
inline DecodeStatus decode(const hal::CanFrame& frame, PoseUncertainty& f) {
  using namespace pose_uncertainty;
  if (const DecodeStatus s = check_frame(kMessage, frame); s != DecodeStatus::ok) return s;
  const std::uint64_t word = data_word(frame);
  const std::int64_t flags = raw_in_word(word, kFlags);
  if ((flags & ~(kFlagExtrapolating | kFlagOutsideRange)) != 0) return DecodeStatus::reserved_bits_set;
  f.r95_position_mm = physical_in_word(word, kR95Position);
  f.r95_orientation_deg = physical_in_word(word, kR95Orientation);
  f.latent_share = physical_in_word(word, kLatentShare);
  f.extrapolating = (flags & kFlagExtrapolating) != 0;
  f.outside_range = (flags & kFlagOutsideRange) != 0;
  f.sequence = static_cast<std::uint8_t>(raw_in_word(word, kSequence));
  return DecodeStatus::ok;
}

inline void encode(const IkReport& f, hal::CanFrame& frame) {
  using namespace ik_report;
  frame = empty_frame(kMessage);
  set_data_word(frame, placed_integer(kSequence, f.sequence) |
                           placed_integer(kOutcome, static_cast<std::int64_t>(f.outcome)) |
                           placed_integer(kIterations, f.iterations) | placed_integer(kCycles, f.cycles) |
                           placed_saturating(kPositionResidual, f.position_residual_mm) |
                           placed_saturating(kOrientationResidual, f.orientation_residual_rad));
}
inline DecodeStatus decode(const hal::CanFrame& frame, IkReport& f) {
  using namespace ik_report;
  if (const DecodeStatus s = check_frame(kMessage, frame); s != DecodeStatus::ok) return s;
  const std::uint64_t word = data_word(frame);
  f.sequence = static_cast<std::uint8_t>(raw_in_word(word, kSequence));
  f.outcome = static_cast<IkOutcome>(raw_in_word(word, kOutcome));
  f.iterations = static_cast<int>(raw_in_word(word, kIterations));
  f.cycles = static_cast<int>(raw_in_word(word, kCycles));
  f.position_residual_mm = physical_in_word(word, kPositionResidual);
  f.orientation_residual_rad = physical_in_word(word, kOrientationResidual);
  return DecodeStatus::ok;
}

inline void encode(const Status& f, hal::CanFrame& frame) {
  using namespace status;
  frame = empty_frame(kMessage);
  set_data_word(frame, placed_integer(kState, static_cast<std::int64_t>(f.state)) |
                           placed_integer(kExtrapolating, f.extrapolating ? 1 : 0) |
                           placed_integer(kHysteresisUnknown, f.hysteresis_unknown ? 1 : 0) |
                           placed_integer(kFault, static_cast<std::int64_t>(f.fault)) |
                           placed_integer(kOverruns, f.overruns) | placed_integer(kExecMax, f.exec_max_us) |
                           placed_integer(kExecMean, f.exec_mean_us));
}
inline DecodeStatus decode(const hal::CanFrame& frame, Status& f) {
  using namespace status;
  if (const DecodeStatus s = check_frame(kMessage, frame); s != DecodeStatus::ok) return s;
  const std::uint64_t word = data_word(frame);
  f.state = static_cast<RuntimeState>(raw_in_word(word, kState));
  f.extrapolating = raw_in_word(word, kExtrapolating) != 0;
  f.hysteresis_unknown = raw_in_word(word, kHysteresisUnknown) != 0;
  f.fault = static_cast<FaultCode>(raw_in_word(word, kFault));
  f.overruns = raw_in_word(word, kOverruns);
  f.exec_max_us = raw_in_word(word, kExecMax);
  f.exec_mean_us = raw_in_word(word, kExecMean);
  return DecodeStatus::ok;
}

inline void encode(const Stats& f, hal::CanFrame& frame) {
  using namespace stats;
  frame = empty_frame(kMessage);
  set_data_word(frame, placed_integer(kJitterMax, f.jitter_max_us) |
                           placed_integer(kRejectedFrames, f.rejected_frames) |
                           placed_integer(kCycleCount, f.cycle_count) |
                           placed_integer(kFaultDetail, f.fault_detail.wire_value()) |
                           placed_integer(kStaleEvents, f.stale_events));
}
// FAULT_DETAIL means something only with the FAULT it details: `reported_fault`
// is the FAULT of the STATUS frame sent with this one.
inline DecodeStatus decode(const hal::CanFrame& frame, FaultCode reported_fault, Stats& f) {
  using namespace stats;
  if (const DecodeStatus s = check_frame(kMessage, frame); s != DecodeStatus::ok) return s;
  const std::uint64_t word = data_word(frame);
  f.jitter_max_us = raw_in_word(word, kJitterMax);
  f.rejected_frames = raw_in_word(word, kRejectedFrames);
  f.cycle_count = static_cast<std::uint16_t>(raw_in_word(word, kCycleCount));
  f.fault_detail = FaultDetail::from_wire(reported_fault, static_cast<std::uint8_t>(raw_in_word(word, kFaultDetail)));
  f.stale_events = raw_in_word(word, kStaleEvents);
  return DecodeStatus::ok;
}

// Model updates (messages.hpp, "Model updates").
struct UpdateCommandFrame {
  UpdateCommand command = UpdateCommand::status;
  std::uint16_t transfer_id = 0;
  std::uint32_t image_size = 0;  // START only; at most 2^24 - 1
};
struct UpdateDigest {
  std::uint8_t part = 0;  // 0..7
  std::uint8_t bytes[4] = {};
};
struct UpdateBlock {
  std::uint16_t block = 0;
  std::uint8_t length = kUpdateBlockBytes;
  std::uint32_t crc = 0;
};
struct UpdateData {
  std::uint8_t bytes[8] = {};
};
struct UpdateReport {
  UpdateState state = UpdateState::idle;
  std::uint8_t active_slot = 0;
  UpdateReason reason = UpdateReason::none;
  std::uint16_t next_block = 0;
  std::uint8_t window = 0;
  std::uint16_t transfer_id = 0;
  std::uint8_t active_sequence = 0;  // low 8 bits
};

// The CRC an UPDATE_BLOCK carries for `size` bytes of block `block`.
inline std::uint32_t update_block_crc(std::uint16_t block, const std::uint8_t* data, std::size_t size) {
  const std::uint8_t number[2] = {static_cast<std::uint8_t>(block & 0xFF), static_cast<std::uint8_t>(block >> 8)};
  return model::crc32(data, size, model::crc32(number, 2));
}

inline void encode(const UpdateCommandFrame& f, hal::CanFrame& frame) {
  using namespace update_command;
  frame = empty_frame(kMessage);
  set_data_word(frame, placed_integer(kCommand, static_cast<std::int64_t>(f.command)) |
                           placed_integer(kTransferId, f.transfer_id) | placed_integer(kImageSize, f.image_size));
}
inline DecodeStatus decode(const hal::CanFrame& frame, UpdateCommandFrame& f) {
  using namespace update_command;
  if (const DecodeStatus s = check_frame(kMessage, frame); s != DecodeStatus::ok) return s;
  const std::uint64_t word = data_word(frame);
  f.command = static_cast<UpdateCommand>(raw_in_word(word, kCommand));
  f.transfer_id = static_cast<std::uint16_t>(raw_in_word(word, kTransferId));
  f.image_size = static_cast<std::uint32_t>(raw_in_word(word, kImageSize));
  return DecodeStatus::ok;
}

inline void encode(const UpdateDigest& f, hal::CanFrame& frame) {
  using namespace update_digest;
  frame = empty_frame(kMessage);
  const std::uint32_t w = std::uint32_t(f.bytes[0]) | (std::uint32_t(f.bytes[1]) << 8) |
                          (std::uint32_t(f.bytes[2]) << 16) | (std::uint32_t(f.bytes[3]) << 24);
  set_data_word(frame, placed_integer(kPart, f.part) | placed_integer(kWord, w));
}
inline DecodeStatus decode(const hal::CanFrame& frame, UpdateDigest& f) {
  using namespace update_digest;
  if (const DecodeStatus s = check_frame(kMessage, frame); s != DecodeStatus::ok) return s;
  const std::uint64_t word = data_word(frame);
  f.part = static_cast<std::uint8_t>(raw_in_word(word, kPart));
  const auto w = static_cast<std::uint32_t>(raw_in_word(word, kWord));
  for (int i = 0; i < 4; ++i) f.bytes[i] = static_cast<std::uint8_t>(w >> (8 * i));
  return DecodeStatus::ok;
}

inline void encode(const UpdateBlock& f, hal::CanFrame& frame) {
  using namespace update_block;
  frame = empty_frame(kMessage);
  set_data_word(frame, placed_integer(kBlock, f.block) | placed_integer(kLength, f.length) |
                           placed_integer(kCrc, f.crc));
}
inline DecodeStatus decode(const hal::CanFrame& frame, UpdateBlock& f) {
  using namespace update_block;
  if (const DecodeStatus s = check_frame(kMessage, frame); s != DecodeStatus::ok) return s;
  const std::uint64_t word = data_word(frame);
  f.block = static_cast<std::uint16_t>(raw_in_word(word, kBlock));
  f.length = static_cast<std::uint8_t>(raw_in_word(word, kLength));
  f.crc = static_cast<std::uint32_t>(raw_in_word(word, kCrc));
  return DecodeStatus::ok;
}

inline void encode(const UpdateData& f, hal::CanFrame& frame) {
  frame = empty_frame(update_data::kMessage);
  for (int i = 0; i < 8; ++i) frame.data[i] = f.bytes[i];
}
inline DecodeStatus decode(const hal::CanFrame& frame, UpdateData& f) {
  if (const DecodeStatus s = check_frame(update_data::kMessage, frame); s != DecodeStatus::ok) return s;
  for (int i = 0; i < 8; ++i) f.bytes[i] = frame.data[i];
  return DecodeStatus::ok;
}

inline void encode(const UpdateReport& f, hal::CanFrame& frame) {
  using namespace update_report;
  frame = empty_frame(kMessage);
  set_data_word(frame, placed_integer(kState, static_cast<std::int64_t>(f.state)) |
                           placed_integer(kActiveSlot, f.active_slot) |
                           placed_integer(kReason, static_cast<std::int64_t>(f.reason)) |
                           placed_integer(kNextBlock, f.next_block) | placed_integer(kWindow, f.window) |
                           placed_integer(kTransferId, f.transfer_id) |
                           placed_integer(kActiveSequence, f.active_sequence));
}
inline DecodeStatus decode(const hal::CanFrame& frame, UpdateReport& f) {
  using namespace update_report;
  if (const DecodeStatus s = check_frame(kMessage, frame); s != DecodeStatus::ok) return s;
  const std::uint64_t word = data_word(frame);
  f.state = static_cast<UpdateState>(raw_in_word(word, kState));
  f.active_slot = static_cast<std::uint8_t>(raw_in_word(word, kActiveSlot));
  f.reason = static_cast<UpdateReason>(raw_in_word(word, kReason));
  f.next_block = static_cast<std::uint16_t>(raw_in_word(word, kNextBlock));
  f.window = static_cast<std::uint8_t>(raw_in_word(word, kWindow));
  f.transfer_id = static_cast<std::uint16_t>(raw_in_word(word, kTransferId));
  f.active_sequence = static_cast<std::uint8_t>(raw_in_word(word, kActiveSequence));
  return DecodeStatus::ok;
}

// What the typed frames assume of the table, checked when this header
// compiles: a signal widened, moved or rescaled in messages.hpp that a struct
// field or a fast path above could no longer follow stops the build instead
// of cutting values short on the bus.
namespace frame_layout {

// Every raw value the signal can carry fits the field it is decoded into.
template <typename Field>
constexpr bool fits(const SignalSpec& signal) {
  using Value = std::conditional_t<std::is_enum_v<Field>, std::underlying_type<Field>, std::common_type<Field>>;
  using Limits = std::numeric_limits<typename Value::type>;
  return signal.raw_minimum >= std::int64_t{Limits::min()} && signal.raw_maximum <= std::int64_t{Limits::max()};
}

// A plain integer: one raw step per unit, no offset.
constexpr bool is_integer(const SignalSpec& signal) { return signal.factor == 1 && signal.offset == 0; }

// cable_frames: one length per signal, L1..L4.
static_assert(std::size(cable_lengths::kSignals) == std::size(CableFeedback{}.lengths_mm));
static_assert(std::size(cable_lengths::kSignals) == std::size(CableSetpoint{}.lengths_mm));
static_assert(fits<TargetMode>(target_position_z::kMode) && fits<std::uint8_t>(target_position_z::kSequence));
static_assert(fits<std::uint8_t>(pose_position_z::kSequence) && fits<std::uint8_t>(pose_uncertainty::kSequence));
static_assert((pose_position_z::kFlagCompensated | pose_position_z::kFlagExtrapolating) <=
              pose_position_z::kFlags.raw_maximum);
static_assert((pose_uncertainty::kFlagExtrapolating | pose_uncertainty::kFlagOutsideRange) <=
              pose_uncertainty::kFlags.raw_maximum);
static_assert(fits<std::uint8_t>(ik_report::kSequence) && fits<IkOutcome>(ik_report::kOutcome) &&
              fits<int>(ik_report::kIterations) && fits<int>(ik_report::kCycles));
static_assert(fits<RuntimeState>(status::kState) && fits<FaultCode>(status::kFault));
static_assert(fits<std::uint16_t>(stats::kCycleCount) && fits<std::uint8_t>(stats::kFaultDetail));
static_assert(fits<UpdateCommand>(update_command::kCommand) && fits<std::uint16_t>(update_command::kTransferId) &&
              fits<std::uint32_t>(update_command::kImageSize));
static_assert(fits<std::uint8_t>(update_digest::kPart));
static_assert(fits<std::uint16_t>(update_block::kBlock) && fits<std::uint8_t>(update_block::kLength) &&
              fits<std::uint32_t>(update_block::kCrc));
static_assert(fits<UpdateState>(update_report::kState) && fits<std::uint8_t>(update_report::kActiveSlot) &&
              fits<UpdateReason>(update_report::kReason) && fits<std::uint16_t>(update_report::kNextBlock) &&
              fits<std::uint8_t>(update_report::kWindow) && fits<std::uint16_t>(update_report::kTransferId) &&
              fits<std::uint8_t>(update_report::kActiveSequence));
// UpdateDigest packs its four bytes into WORD, little-endian.
static_assert(update_digest::kWord.length_bits == 32 && !update_digest::kWord.is_signed &&
              is_integer(update_digest::kWord));
// UpdateData copies the frame's bytes as they are: DATA_LOW is bytes 0..3,
// DATA_HIGH bytes 4..7, both plain unsigned words.
static_assert(update_data::kDataLow.start_bit == 0 && update_data::kDataLow.length_bits == 32 &&
              !update_data::kDataLow.is_signed && is_integer(update_data::kDataLow));
static_assert(update_data::kDataHigh.start_bit == 32 && update_data::kDataHigh.length_bits == 32 &&
              !update_data::kDataHigh.is_signed && is_integer(update_data::kDataHigh));
static_assert(update_data::kMessage.dlc == 8 && update_data::kMessage.signals.count == 2);

}  // namespace frame_layout

}  // namespace cdcr::firmware::protocol
