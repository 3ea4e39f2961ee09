#pragma once
// The runtime's CAN protocol: identifiers, signal layouts and scalings. This
// header is the single source of truth for the code; firmware/protocol/cdcr.dbc
// describes the same frames for candump/cantools users, and a host test checks
// that both agree signal by signal.
//
// All signals are little-endian and byte-aligned. Lengths in 0.01 mm,
// quaternions (Hamilton, w first) in Q15 with 1.0 = 32767.
//
//   id           name                 dlc  sender   content
//   0x100+s      CABLE_FEEDBACK_s     8    drives   segment s's 4 cable lengths, u16 x 0.01 mm
//   0x110+s      CABLE_SETPOINT_s     8    runtime  segment s's 4 commanded cable lengths, u16 x 0.01 mm
//   0x120        TARGET_ORIENTATION   8    host     target quaternion, i16 Q15 (before the commit frame)
//   0x121        TARGET_POSITION_XY   8    host     target x, y, i32 x 0.01 mm
//   0x122        TARGET_POSITION_Z    6    host     target z, mode, sequence: commits the target
//   0x130        POSE_POSITION_XY     8    runtime  tip x, y, i32 x 0.01 mm
//   0x131        POSE_POSITION_Z      6    runtime  tip z, flags, sequence
//   0x132        POSE_ORIENTATION     8    runtime  tip quaternion, i16 Q15
//   0x140        IK_REPORT            6    runtime  outcome of the last target
//   0x150        STATUS               8    runtime  heartbeat: state, fault, overruns, execution time
//   0x151        STATS                8    runtime  jitter, rejected frames, cycle counter, detail

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "cdcr/hal/can_bus.hpp"

namespace cdcr::firmware::protocol {

inline constexpr std::uint32_t kCableFeedbackBaseId = 0x100;
inline constexpr std::uint32_t kCableSetpointBaseId = 0x110;
inline constexpr int kSegmentIdSlots = 8;  // ids base .. base + 7
inline constexpr std::uint32_t kTargetOrientationId = 0x120;
inline constexpr std::uint32_t kTargetPositionXyId = 0x121;
inline constexpr std::uint32_t kTargetPositionZId = 0x122;
inline constexpr std::uint32_t kPosePositionXyId = 0x130;
inline constexpr std::uint32_t kPosePositionZId = 0x131;
inline constexpr std::uint32_t kPoseOrientationId = 0x132;
inline constexpr std::uint32_t kIkReportId = 0x140;
inline constexpr std::uint32_t kStatusId = 0x150;
inline constexpr std::uint32_t kStatsId = 0x151;

// u16 at 0.01 mm spans 0..655.34 mm, several times the longest cable of the
// prototype (L + r * theta_max ~ 225 mm); 0xFFFF means "not available".
inline constexpr double kLengthScaleMm = 0.01;
inline constexpr std::uint16_t kCableNotAvailable = 0xFFFF;
inline constexpr double kMaxCableLengthMm = 655.34;
// i32 at 0.01 mm spans +-21 km: positions never saturate.
inline constexpr double kPositionScaleMm = 0.01;
inline constexpr double kQuaternionScale = 1.0 / 32767.0;
// A received quaternion must have a norm within this of 1 (Q15 rounding
// moves it by at most ~1e-4).
inline constexpr double kQuaternionNormTolerance = 1e-2;
inline constexpr double kTimeScaleUs = 1.0;

enum class TargetMode : std::uint8_t { position = 0, pose = 1 };

enum class IkOutcome : std::uint8_t {
  converged = 0,         // setpoints published
  unreachable = 1,       // no converged solution; setpoints held
  rejected_malformed = 2,// the target frames were inconsistent; setpoints held
  rejected_state = 3,    // the runtime is in FAULT; setpoints held
};

// POSE_POSITION_Z FLAGS bits.
inline constexpr std::uint8_t kPoseFlagCompensated = 0x01;

struct SignalSpec {
  const char* name;
  std::uint8_t start_bit;    // byte-aligned, little-endian (DBC @1)
  std::uint8_t length_bits;  // 8, 16 or 32
  bool is_signed;
  double factor;
  double offset;
  double minimum;
  double maximum;
  const char* unit;
};

struct MessageSpec {
  const char* name;
  std::uint32_t id;
  std::uint8_t dlc;
  const char* sender;
  const SignalSpec* signals;
  std::uint8_t signal_count;
};

namespace signal {
inline constexpr SignalSpec cable[4] = {
    {"L1", 0, 16, false, kLengthScaleMm, 0, 0, 655.35, "mm"},
    {"L2", 16, 16, false, kLengthScaleMm, 0, 0, 655.35, "mm"},
    {"L3", 32, 16, false, kLengthScaleMm, 0, 0, 655.35, "mm"},
    {"L4", 48, 16, false, kLengthScaleMm, 0, 0, 655.35, "mm"},
};
inline constexpr SignalSpec quaternion[4] = {
    {"QW", 0, 16, true, kQuaternionScale, 0, -1, 1, ""},
    {"QX", 16, 16, true, kQuaternionScale, 0, -1, 1, ""},
    {"QY", 32, 16, true, kQuaternionScale, 0, -1, 1, ""},
    {"QZ", 48, 16, true, kQuaternionScale, 0, -1, 1, ""},
};
inline constexpr SignalSpec position_xy[2] = {
    {"X", 0, 32, true, kPositionScaleMm, 0, -21474836.48, 21474836.47, "mm"},
    {"Y", 32, 32, true, kPositionScaleMm, 0, -21474836.48, 21474836.47, "mm"},
};
inline constexpr SignalSpec target_z[3] = {
    {"Z", 0, 32, true, kPositionScaleMm, 0, -21474836.48, 21474836.47, "mm"},
    {"MODE", 32, 8, false, 1, 0, 0, 1, ""},
    {"SEQUENCE", 40, 8, false, 1, 0, 0, 255, ""},
};
inline constexpr SignalSpec pose_z[3] = {
    {"Z", 0, 32, true, kPositionScaleMm, 0, -21474836.48, 21474836.47, "mm"},
    {"FLAGS", 32, 8, false, 1, 0, 0, 255, ""},
    {"SEQUENCE", 40, 8, false, 1, 0, 0, 255, ""},
};
inline constexpr SignalSpec ik_report[5] = {
    {"SEQUENCE", 0, 8, false, 1, 0, 0, 255, ""},
    {"OUTCOME", 8, 8, false, 1, 0, 0, 3, ""},
    {"ITERATIONS", 16, 8, false, 1, 0, 0, 255, ""},
    {"MODEL_STATUS", 24, 8, false, 1, 0, 0, 255, ""},
    {"POSITION_ERROR", 32, 16, false, kLengthScaleMm, 0, 0, 655.35, "mm"},
};
inline constexpr SignalSpec status[5] = {
    {"STATE", 0, 8, false, 1, 0, 0, 3, ""},
    {"FAULT", 8, 8, false, 1, 0, 0, 255, ""},
    {"OVERRUNS", 16, 16, false, 1, 0, 0, 65535, ""},
    {"EXEC_MAX", 32, 16, false, kTimeScaleUs, 0, 0, 65535, "us"},
    {"EXEC_MEAN", 48, 16, false, kTimeScaleUs, 0, 0, 65535, "us"},
};
inline constexpr SignalSpec stats[5] = {
    {"JITTER_MAX", 0, 16, false, kTimeScaleUs, 0, 0, 65535, "us"},
    {"REJECTED_FRAMES", 16, 16, false, 1, 0, 0, 65535, ""},
    {"CYCLE_COUNT", 32, 16, false, 1, 0, 0, 65535, ""},
    {"FAULT_DETAIL", 48, 8, false, 1, 0, 0, 255, ""},
    {"STALE_EVENTS", 56, 8, false, 1, 0, 0, 255, ""},
};
}  // namespace signal

// Every frame of the protocol, as the DBC lists them.
inline constexpr MessageSpec kMessages[] = {
    {"CABLE_FEEDBACK_0", kCableFeedbackBaseId + 0, 8, "DRIVES", signal::cable, 4},
    {"CABLE_FEEDBACK_1", kCableFeedbackBaseId + 1, 8, "DRIVES", signal::cable, 4},
    {"CABLE_FEEDBACK_2", kCableFeedbackBaseId + 2, 8, "DRIVES", signal::cable, 4},
    {"CABLE_FEEDBACK_3", kCableFeedbackBaseId + 3, 8, "DRIVES", signal::cable, 4},
    {"CABLE_FEEDBACK_4", kCableFeedbackBaseId + 4, 8, "DRIVES", signal::cable, 4},
    {"CABLE_FEEDBACK_5", kCableFeedbackBaseId + 5, 8, "DRIVES", signal::cable, 4},
    {"CABLE_FEEDBACK_6", kCableFeedbackBaseId + 6, 8, "DRIVES", signal::cable, 4},
    {"CABLE_FEEDBACK_7", kCableFeedbackBaseId + 7, 8, "DRIVES", signal::cable, 4},
    {"CABLE_SETPOINT_0", kCableSetpointBaseId + 0, 8, "RUNTIME", signal::cable, 4},
    {"CABLE_SETPOINT_1", kCableSetpointBaseId + 1, 8, "RUNTIME", signal::cable, 4},
    {"CABLE_SETPOINT_2", kCableSetpointBaseId + 2, 8, "RUNTIME", signal::cable, 4},
    {"CABLE_SETPOINT_3", kCableSetpointBaseId + 3, 8, "RUNTIME", signal::cable, 4},
    {"CABLE_SETPOINT_4", kCableSetpointBaseId + 4, 8, "RUNTIME", signal::cable, 4},
    {"CABLE_SETPOINT_5", kCableSetpointBaseId + 5, 8, "RUNTIME", signal::cable, 4},
    {"CABLE_SETPOINT_6", kCableSetpointBaseId + 6, 8, "RUNTIME", signal::cable, 4},
    {"CABLE_SETPOINT_7", kCableSetpointBaseId + 7, 8, "RUNTIME", signal::cable, 4},
    {"TARGET_ORIENTATION", kTargetOrientationId, 8, "HOST", signal::quaternion, 4},
    {"TARGET_POSITION_XY", kTargetPositionXyId, 8, "HOST", signal::position_xy, 2},
    {"TARGET_POSITION_Z", kTargetPositionZId, 6, "HOST", signal::target_z, 3},
    {"POSE_POSITION_XY", kPosePositionXyId, 8, "RUNTIME", signal::position_xy, 2},
    {"POSE_POSITION_Z", kPosePositionZId, 6, "RUNTIME", signal::pose_z, 3},
    {"POSE_ORIENTATION", kPoseOrientationId, 8, "RUNTIME", signal::quaternion, 4},
    {"IK_REPORT", kIkReportId, 6, "RUNTIME", signal::ik_report, 5},
    {"STATUS", kStatusId, 8, "RUNTIME", signal::status, 5},
    {"STATS", kStatsId, 8, "RUNTIME", signal::stats, 5},
};

// Raw (unscaled) access to a signal's bits.
inline std::int64_t get_raw(const hal::CanFrame& frame, const SignalSpec& spec) {
  const int first = spec.start_bit / 8;
  // Clamped to the frame so a malformed spec cannot read past it.
  const int bytes = first + spec.length_bits / 8 > 8 ? 8 - first : spec.length_bits / 8;
  std::uint64_t value = 0;
  for (int i = bytes - 1; i >= 0; --i) value = (value << 8) | frame.data[first + i];
  if (spec.is_signed && spec.length_bits < 64) {
    const std::uint64_t sign = std::uint64_t{1} << (spec.length_bits - 1);
    if (value & sign) return static_cast<std::int64_t>(value) - static_cast<std::int64_t>(sign << 1);
  }
  return static_cast<std::int64_t>(value);
}

inline void put_raw(hal::CanFrame& frame, const SignalSpec& spec, std::int64_t raw) {
  const int first = spec.start_bit / 8;
  const int bytes = spec.length_bits / 8;
  std::uint64_t value = static_cast<std::uint64_t>(raw);
  for (int i = 0; i < bytes && first + i < 8; ++i) {
    frame.data[first + i] = static_cast<std::uint8_t>(value & 0xFF);
    value >>= 8;
  }
}

inline std::int64_t raw_minimum(const SignalSpec& spec) {
  return spec.is_signed ? -(std::int64_t{1} << (spec.length_bits - 1)) : 0;
}
inline std::int64_t raw_maximum(const SignalSpec& spec) {
  return spec.is_signed ? (std::int64_t{1} << (spec.length_bits - 1)) - 1 : (std::int64_t{1} << spec.length_bits) - 1;
}

// Rounds to the nearest raw value and saturates at the signal's raw range
// (NaN encodes as the raw minimum; senders validate before encoding).
inline std::int64_t to_raw(const SignalSpec& spec, double value) {
  const double scaled = (value - spec.offset) / spec.factor;
  if (!(scaled >= double(raw_minimum(spec)))) return raw_minimum(spec);
  if (scaled >= double(raw_maximum(spec))) return raw_maximum(spec);
  return static_cast<std::int64_t>(std::llround(scaled));
}

inline double from_raw(const SignalSpec& spec, std::int64_t raw) { return double(raw) * spec.factor + spec.offset; }

inline void put(hal::CanFrame& frame, const SignalSpec& spec, double value) { put_raw(frame, spec, to_raw(spec, value)); }
inline double get(const hal::CanFrame& frame, const SignalSpec& spec) { return from_raw(spec, get_raw(frame, spec)); }

inline hal::CanFrame make_frame(std::uint32_t id, std::uint8_t dlc) {
  hal::CanFrame frame;
  frame.id = id;
  frame.dlc = dlc;
  return frame;
}

// Cable frames (feedback and setpoint share the layout). Lengths beyond the
// encodable range are refused rather than saturated: a clipped cable length
// is a wrong one.
inline bool encode_cables(std::uint32_t id, const double (&lengths_mm)[4], hal::CanFrame& frame) {
  frame = make_frame(id, 8);
  for (int k = 0; k < 4; ++k) {
    if (!(lengths_mm[k] > 0.0) || !(lengths_mm[k] <= kMaxCableLengthMm)) return false;
    put(frame, signal::cable[k], lengths_mm[k]);
  }
  return true;
}

enum class CableFrameStatus : std::uint8_t { ok, wrong_dlc, not_available, not_positive };

inline CableFrameStatus decode_cables(const hal::CanFrame& frame, double (&lengths_mm)[4]) {
  if (frame.dlc != 8) return CableFrameStatus::wrong_dlc;
  for (int k = 0; k < 4; ++k) {
    const std::int64_t raw = get_raw(frame, signal::cable[k]);
    if (raw == kCableNotAvailable) return CableFrameStatus::not_available;
    if (raw == 0) return CableFrameStatus::not_positive;
    lengths_mm[k] = from_raw(signal::cable[k], raw);
  }
  return CableFrameStatus::ok;
}

inline bool is_cable_feedback(std::uint32_t id) {
  return id >= kCableFeedbackBaseId && id < kCableFeedbackBaseId + kSegmentIdSlots;
}
inline bool is_cable_setpoint(std::uint32_t id) {
  return id >= kCableSetpointBaseId && id < kCableSetpointBaseId + kSegmentIdSlots;
}

}  // namespace cdcr::firmware::protocol
