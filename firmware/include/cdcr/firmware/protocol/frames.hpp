#pragma once
// The protocol's messages as typed frames: one struct per message, its fields
// named after the DBC signals, and which field carries which signal. The
// encoder and decoder of every frame are frame_codec.hpp's, walking the
// signal table of messages.hpp, so each signal's bits are written down once.
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
#include <limits>

#include "cdcr/firmware/fault.hpp"
#include "cdcr/firmware/fault_detail.hpp"
#include "cdcr/firmware/protocol/frame_codec.hpp"
#include "cdcr/firmware/protocol/message_codec.hpp"
#include "cdcr/firmware/protocol/messages.hpp"
#include "cdcr/firmware/protocol/signal_codec.hpp"
#include "cdcr/hal/can_bus.hpp"
#include "cdcr/model/crc32.hpp"

namespace cdcr::firmware::protocol {

// CABLE_FEEDBACK_s and CABLE_SETPOINT_s: the four cable lengths of a segment.
// L1..L4; a segment of three cables has no L4: NaN here, "not available"
// on the wire.
struct CableFeedback {
  int segment = 0;
  double lengths_mm[4] = {};
};
struct CableSetpoint {
  int segment = 0;
  double lengths_mm[4] = {};
};

// Segment `segment`'s frame from a robot's cable vector (segment by
// segment): its `count` cables from `first`, then not available.
template <typename Frame, typename Vector>
Frame segment_cables_frame(int segment, const Vector& cables_mm, int first, int count) {
  Frame frame;
  frame.segment = segment;
  for (int k = 0; k < 4; ++k) {
    frame.lengths_mm[k] = k < count ? double(cables_mm[first + k]) : std::numeric_limits<double>::quiet_NaN();
  }
  return frame;
}

// PAYLOAD: kg.
// The homing move has ended: the robot is at home (HOMING).
struct Homing {
  bool at_home = true;
};

struct Payload {
  double payload_kg = 0;
};

// What the host asks of the drives (DRIVES_COMMAND).
enum class DrivesCommandKind : std::uint8_t { recover = 1 };
struct DrivesCommand {
  DrivesCommandKind command = DrivesCommandKind::recover;
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
  bool radii = false;          // FLAGS bit 2: POSE_FD's uncertainty part holds radii (POSE_FD only)
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

inline bool cable_length_encodable(double length_mm) {
  std::int64_t raw = 0;
  return cable_length_raw(cable_lengths::kL1, length_mm, raw);
}

// The length a receiver decodes for `length_mm` (which must be encodable).
inline double cable_length_as_transmitted(double length_mm) { return as_transmitted(cable_lengths::kL1, length_mm); }

// Which field carries which signal, in the order of the message's signals
// in messages.hpp; encode() and decode() are frame_codec.hpp's.
template <>
struct FrameFields<CableFeedback>
    : SegmentFields<cable_feedback::kMessage, &CableFeedback::segment,
                    field::CableLengths<&CableFeedback::lengths_mm>> {};
template <>
struct FrameFields<CableSetpoint>
    : SegmentFields<cable_setpoint::kMessage, &CableSetpoint::segment,
                    field::CableLengths<&CableSetpoint::lengths_mm>> {};

template <>
struct FrameFields<TargetOrientation>
    : MessageFields<target_orientation::kMessage, field::Value<&TargetOrientation::qw>,
                    field::Value<&TargetOrientation::qx>, field::Value<&TargetOrientation::qy>,
                    field::Value<&TargetOrientation::qz>> {};
template <>
struct FrameFields<TargetPositionXy>
    : MessageFields<target_position_xy::kMessage, field::Value<&TargetPositionXy::x_mm>,
                    field::Value<&TargetPositionXy::y_mm>> {};
template <>
struct FrameFields<TargetPositionZ>
    : MessageFields<target_position_z::kMessage, field::Value<&TargetPositionZ::z_mm>,
                    field::Value<&TargetPositionZ::mode>, field::Value<&TargetPositionZ::tracking>,
                    field::Value<&TargetPositionZ::refuse_extrapolating>,
                    field::Value<&TargetPositionZ::sequence>> {};

template <>
struct FrameFields<PosePositionXy>
    : MessageFields<pose_position_xy::kMessage, field::Value<&PosePositionXy::x_mm>,
                    field::Value<&PosePositionXy::y_mm>> {};
template <>
struct FrameFields<PosePositionZ>
    : MessageFields<pose_position_z::kMessage, field::Value<&PosePositionZ::z_mm>,
                    field::FlagSet<field::Flag<pose_position_z::kFlagCompensated, &PosePositionZ::compensated>,
                                   field::Flag<pose_position_z::kFlagExtrapolating, &PosePositionZ::extrapolating>,
                                   field::Flag<pose_position_z::kFlagRadii, &PosePositionZ::radii>>,
                    field::Value<&PosePositionZ::sequence>> {};
template <>
struct FrameFields<PoseOrientation>
    : MessageFields<pose_orientation::kMessage, field::Value<&PoseOrientation::qw>,
                    field::Value<&PoseOrientation::qx>, field::Value<&PoseOrientation::qy>,
                    field::Value<&PoseOrientation::qz>> {};
template <>
struct FrameFields<PoseUncertainty>
    : MessageFields<pose_uncertainty::kMessage, field::Value<&PoseUncertainty::r95_position_mm>,
                    field::Value<&PoseUncertainty::r95_orientation_deg>,
                    field::Value<&PoseUncertainty::latent_share>,
                    field::FlagSet<field::Flag<pose_uncertainty::kFlagExtrapolating, &PoseUncertainty::extrapolating>,
                                   field::Flag<pose_uncertainty::kFlagOutsideRange, &PoseUncertainty::outside_range>>,
                    field::Value<&PoseUncertainty::sequence>> {};

template <>
struct FrameFields<IkReport>
    : MessageFields<ik_report::kMessage, field::Value<&IkReport::sequence>, field::Value<&IkReport::outcome>,
                    field::Value<&IkReport::iterations>, field::Value<&IkReport::cycles>,
                    field::Value<&IkReport::position_residual_mm>,
                    field::Value<&IkReport::orientation_residual_rad>> {};

template <>
struct FrameFields<Status>
    : MessageFields<status::kMessage, field::Value<&Status::state>, field::Value<&Status::extrapolating>,
                    field::Value<&Status::hysteresis_unknown>, field::Value<&Status::fault>,
                    field::Value<&Status::overruns>, field::Value<&Status::exec_max_us>,
                    field::Value<&Status::exec_mean_us>> {};
template <>
struct FrameFields<Stats>
    : MessageFields<stats::kMessage, field::Value<&Stats::jitter_max_us>, field::Value<&Stats::rejected_frames>,
                    field::Value<&Stats::cycle_count>, field::Detail<&Stats::fault_detail>,
                    field::Value<&Stats::stale_events>> {};

// FAULT_DETAIL means something only with the FAULT it details: `reported_fault`
// is the FAULT of the STATUS frame sent with this one.
inline DecodeStatus decode(const hal::CanFrame& frame, FaultCode reported_fault, Stats& f) {
  return FrameFields<Stats>::decode(frame, f, reported_fault);
}

// A payload outside the signal's range (or NaN) is refused: the encoder
// returns false and leaves the frame alone.
template <>
struct FrameFields<Payload> : MessageFields<payload::kMessage, field::Refused<&Payload::payload_kg>> {};
template <>
struct FrameFields<Homing> : MessageFields<homing::kMessage, field::Value<&Homing::at_home>> {};
template <>
struct FrameFields<DrivesCommand> : MessageFields<drives_command::kMessage, field::Value<&DrivesCommand::command>> {};

// The SEQUENCE of a TARGET_POSITION_Z frame that did not decode, so that
// the rejection can name its target; 0 when the frame is too short to hold one.
inline std::uint8_t commit_sequence(const hal::CanFrame& frame) {
  const SignalSpec& sequence = target_position_z::kSequence;
  if (8 * frame.dlc < sequence.start_bit + sequence.length_bits) return 0;
  return static_cast<std::uint8_t>(read_raw(frame, sequence));
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

template <>
struct FrameFields<UpdateCommandFrame>
    : MessageFields<update_command::kMessage, field::Value<&UpdateCommandFrame::command>,
                    field::Value<&UpdateCommandFrame::transfer_id>, field::Value<&UpdateCommandFrame::image_size>> {};
template <>
struct FrameFields<UpdateDigest> : MessageFields<update_digest::kMessage, field::Value<&UpdateDigest::part>,
                                                 field::Bytes<&UpdateDigest::bytes, 0>> {};
template <>
struct FrameFields<UpdateBlock>
    : MessageFields<update_block::kMessage, field::Value<&UpdateBlock::block>, field::Value<&UpdateBlock::length>,
                    field::Value<&UpdateBlock::crc>> {};
template <>
struct FrameFields<UpdateData> : MessageFields<update_data::kMessage, field::Bytes<&UpdateData::bytes, 0>,
                                               field::Bytes<&UpdateData::bytes, 4>> {};
template <>
struct FrameFields<UpdateReport>
    : MessageFields<update_report::kMessage, field::Value<&UpdateReport::state>,
                    field::Value<&UpdateReport::active_slot>, field::Value<&UpdateReport::reason>,
                    field::Value<&UpdateReport::next_block>, field::Value<&UpdateReport::window>,
                    field::Value<&UpdateReport::transfer_id>, field::Value<&UpdateReport::active_sequence>> {};

}  // namespace cdcr::firmware::protocol
