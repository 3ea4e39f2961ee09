#pragma once
// Every message and signal of the runtime's CAN protocol, once: identifiers,
// DLC, sender and receiver, each signal's bits, scaling, range and unit, the
// value tables of the enums, the acceptance filter of each frame group, and
// the comments of the DBC file. This is the protocol's only description:
// frame_codec.hpp encodes and decodes the messages from it, and the build
// writes the DBC file for candump/cantools users from it
// (firmware/protocol/write_dbc.cpp, into <build>/firmware/protocol/cdcr.dbc).
// host_tests/firmware/protocol_golden_frames_test.cpp holds a frame of every
// message written out by hand, so a wrong start bit or scale here fails.

#include <cstdint>

#include "cdcr/firmware/fault.hpp"
#include "cdcr/firmware/protocol/message_codec.hpp"
#include "cdcr/firmware/protocol/signal_codec.hpp"
#include "cdcr/hal/can_bus.hpp"

namespace cdcr::firmware::protocol {

// The database as a whole: the DBC's VERSION, its nodes (BU_) and its
// first comment.
inline constexpr const char* kDbcVersion = "cdcr runtime protocol 2";
inline constexpr const char* kDbcNodes[] = {"RUNTIME", "DRIVES", "HOST"};
inline constexpr const char* kDbcComment =
    "Cable-driven continuum robot runtime. Little-endian (Intel) signals. Lengths 0.01 mm, quaternions Hamilton "
    "w-first in Q15 (1.0 = 32767). Bits no signal defines are reserved and sent as 0. Generated from the runtime's "
    "codec table, firmware/include/cdcr/firmware/protocol/messages.hpp: change the protocol there, not here.";

// Every identifier of the protocol lies in a window of kIdWindow from its
// base: the identifiers written in this table are at kDefaultIdBase. A bus
// whose identifiers there are taken (on a CANopen network 0x100 is TIME and
// 0x101-0x180 are restricted, CiA 301) moves the whole window to another
// base, a multiple of 8 with the window within the 11-bit space: the
// runtime, the drives, the host and the DBC then send and read every frame
// shifted by id_offset() (hal/shifted_can_bus.hpp).
inline constexpr std::uint32_t kDefaultIdBase = 0x100;
inline constexpr std::uint32_t kIdWindow = 0x80;
constexpr bool is_valid_id_base(std::uint32_t base) {
  return base % 8 == 0 && base + kIdWindow <= hal::kMaxStandardId + 1;
}
// What to add to a table identifier to get the one on the bus (mod 2,048).
constexpr std::uint32_t id_offset(std::uint32_t base) {
  return (base + hal::kMaxStandardId + 1 - kDefaultIdBase) % (hal::kMaxStandardId + 1);
}

// Per-segment messages reserve this many identifiers (base .. base + 7).
inline constexpr int kSegmentIdSlots = 8;

// Frame groups, one acceptance filter each: the filter passes every message
// of its group and no other message of the protocol (a test checks it).
inline constexpr hal::CanFilter kCableFeedbackFrames{0x100, 0x7F8};  // CABLE_FEEDBACK_0..7
inline constexpr hal::CanFilter kCableSetpointFrames{0x110, 0x7F8};  // CABLE_SETPOINT_0..7
inline constexpr hal::CanFilter kTargetFrames{0x120, 0x7FC};         // TARGET_ORIENTATION, _POSITION_XY, _POSITION_Z, TARGET_FD
inline constexpr hal::CanFilter kCableSetpointsFdFrames{0x118, 0x7F8};  // CABLE_SETPOINTS_FD_0..1
inline constexpr hal::CanFilter kPoseFrames{0x130, 0x7F8};           // POSE_POSITION_XY, _POSITION_Z, _ORIENTATION, _UNCERTAINTY, POSE_FD
inline constexpr hal::CanFilter kIkReportFrames{0x140, 0x7FF};       // IK_REPORT
inline constexpr hal::CanFilter kStatusFrames{0x150, 0x7FE};         // STATUS, STATS
inline constexpr hal::CanFilter kPayloadFrames{0x160, 0x7FC};        // PAYLOAD, HOMING, DRIVES_COMMAND

enum class TargetMode : std::uint8_t { position = 0, pose = 1 };

enum class IkOutcome : std::uint8_t {
  converged = 0,           // setpoints published
  unreachable = 1,         // no acceptable solution; setpoints held (STATS FAULT_DETAIL: model::Status)
  rejected_malformed = 2,  // the target frames were inconsistent; setpoints held
  rejected_state = 3,      // the runtime is in FAULT or BOOT; setpoints held
  superseded = 4,          // a newer target replaced this one before it finished
  aborted_fault = 5,       // the runtime entered FAULT while solving
  in_progress = 6,         // periodic report while a solve runs
  // The solution extrapolates (outside the fitted input range, or the
  // variance says so) and the target asked for such solutions to be
  // refused (REFUSE_EXTRAPOLATING); setpoints held.
  refused_extrapolating = 7,
};

// Scalings. u16 at 0.01 mm spans 0..655.34 mm for cables, several times the
// longest cable of the prototype (L + r * theta_max ~ 225 mm); raw 0xFFFF
// means "not available". i32 at 0.01 mm spans +-21 km: positions never
// saturate. Quaternions (Hamilton, w first) in Q15 with 1.0 = 32767.
inline constexpr double kLengthScaleMm = 0.01;
inline constexpr double kQuaternionScale = 1.0 / 32767.0;
inline constexpr std::int64_t kCableNotAvailableRaw = 0xFFFF;
// A received quaternion's norm: model/unit_quaternion.hpp.

namespace values {
inline constexpr ValueName kTargetMode[] = {{0, "position"}, {1, "pose"}};
inline constexpr ValueName kIkOutcome[] = {
    {0, "converged"},     {1, "unreachable"},   {2, "rejected_malformed"}, {3, "rejected_state"},
    {4, "superseded"},    {5, "aborted_fault"}, {6, "in_progress"}, {7, "refused_extrapolating"},
};
inline constexpr ValueName kRuntimeState[] = {{0, "BOOT"}, {1, "RUN"}, {2, "DEGRADED"}, {3, "FAULT"}};
inline constexpr ValueName kFaultCode[] = {
    {0, "none"},
    {1, "image_missing"},
    {2, "image_invalid"},
    {3, "image_geometry_invalid"},
    {4, "cable_input_stale"},
    {5, "cable_frame_malformed"},
    {6, "cable_lengths_invalid"},
    {7, "target_malformed"},
    {8, "target_unreachable"},
    {9, "can_transmit_failed"},
    {10, "can_filters_refused"},
    {11, "payload_invalid"},
    {12, "homing_malformed"},
    {13, "drive_silent"},
    {14, "drive_fault"},
    {15, "drive_refused"},
    {16, "drives_command_malformed"},
};
inline constexpr ValueName kDrivesCommand[] = {{1, "recover"}};
}  // namespace values

// Layouts shared by several messages.
namespace cable_lengths {
inline constexpr SignalSpec kL1{"L1", 0, 16, false, kLengthScaleMm, 0, 0, 655.35, "mm"};
inline constexpr SignalSpec kL2{"L2", 16, 16, false, kLengthScaleMm, 0, 0, 655.35, "mm"};
inline constexpr SignalSpec kL3{"L3", 32, 16, false, kLengthScaleMm, 0, 0, 655.35, "mm"};
inline constexpr SignalSpec kL4{"L4", 48, 16, false, kLengthScaleMm, 0, 0, 655.35, "mm"};
inline constexpr const SignalSpec* kSignals[] = {&kL1, &kL2, &kL3, &kL4};
}  // namespace cable_lengths

namespace quaternion {
inline constexpr SignalSpec kQw{"QW", 0, 16, true, kQuaternionScale, 0, -1, 1, ""};
inline constexpr SignalSpec kQx{"QX", 16, 16, true, kQuaternionScale, 0, -1, 1, ""};
inline constexpr SignalSpec kQy{"QY", 32, 16, true, kQuaternionScale, 0, -1, 1, ""};
inline constexpr SignalSpec kQz{"QZ", 48, 16, true, kQuaternionScale, 0, -1, 1, ""};
inline constexpr const SignalSpec* kSignals[] = {&kQw, &kQx, &kQy, &kQz};
}  // namespace quaternion

namespace position_xy {
inline constexpr SignalSpec kX{"X", 0, 32, true, kLengthScaleMm, 0, -21474836.48, 21474836.47, "mm"};
inline constexpr SignalSpec kY{"Y", 32, 32, true, kLengthScaleMm, 0, -21474836.48, 21474836.47, "mm"};
inline constexpr const SignalSpec* kSignals[] = {&kX, &kY};
}  // namespace position_xy

// 0x100 + s: achieved cable lengths of segment s, from the drives.
namespace cable_feedback {
inline constexpr MessageSpec kMessage{
    "CABLE_FEEDBACK", 0x100, kSegmentIdSlots, 8, "DRIVES", signal_list(cable_lengths::kSignals), kCableFeedbackFrames};
inline constexpr MessageNotes kNotes{
    &kMessage, "RUNTIME",
    "Achieved cable lengths of segment {segment}; raw 65535 = not available, 0 is invalid. A segment of three cables "
    "has no L4: 65535."};
}

// 0x110 + s: commanded cable lengths of segment s.
namespace cable_setpoint {
inline constexpr MessageSpec kMessage{
    "CABLE_SETPOINT", 0x110, kSegmentIdSlots, 8, "RUNTIME", signal_list(cable_lengths::kSignals), kCableSetpointFrames};
inline constexpr MessageNotes kNotes{&kMessage, "DRIVES",
                                     "Commanded cable lengths of segment {segment}; a segment of three cables has no "
                                     "L4: 65535."};
}

// 0x120: target orientation, before the commit frame of a pose target.
namespace target_orientation {
inline constexpr MessageSpec kMessage{
    "TARGET_ORIENTATION", 0x120, 1, 8, "HOST", signal_list(quaternion::kSignals), kTargetFrames};
inline constexpr MessageNotes kNotes{&kMessage, "RUNTIME",
                                     "Target orientation; must precede TARGET_POSITION_Z when MODE = 1."};
}

// 0x121: target x, y, before the commit frame.
namespace target_position_xy {
inline constexpr MessageSpec kMessage{
    "TARGET_POSITION_XY", 0x121, 1, 8, "HOST", signal_list(position_xy::kSignals), kTargetFrames};
inline constexpr MessageNotes kNotes{&kMessage, "RUNTIME", "Target position x, y; must precede TARGET_POSITION_Z."};
}

// 0x122: target z; commits the target. Bits 35..39 are reserved and must be 0.
namespace target_position_z {
inline constexpr SignalSpec kZ{"Z", 0, 32, true, kLengthScaleMm, 0, -21474836.48, 21474836.47, "mm"};
inline constexpr SignalSpec kMode{"MODE", 32, 1, false, 1, 0, 0, 1, "", value_table(values::kTargetMode)};
// 1: one target of a stream along a path; the solver warm-starts from its
// last solution and may publish the best point so far.
inline constexpr SignalSpec kTracking{"TRACKING", 33, 1, false, 1, 0, 0, 1, ""};
// 1: a solution where the model extrapolates is not sent: the request ends
// as refused_extrapolating, and no best point so far goes out before the
// solution has been checked.
inline constexpr SignalSpec kRefuseExtrapolating{"REFUSE_EXTRAPOLATING", 34, 1, false, 1, 0, 0, 1, ""};
inline constexpr SignalSpec kSequence{"SEQUENCE", 40, 8, false, 1, 0, 0, 255, ""};
inline constexpr const SignalSpec* kSignals[] = {&kZ, &kMode, &kTracking, &kRefuseExtrapolating, &kSequence};
inline constexpr MessageSpec kMessage{"TARGET_POSITION_Z", 0x122, 1, 6, "HOST", signal_list(kSignals), kTargetFrames};
inline constexpr SignalNote kSignalNotes[] = {
    {&kTracking,
     "1: this target is one of a stream along a path; the solver warm-starts from its last solution and may publish "
     "the best point so far."},
    {&kRefuseExtrapolating,
     "1: a solution where the model extrapolates (outside its fitted input range, or by its variance) is not sent: "
     "IK_REPORT OUTCOME 7 (refused_extrapolating), setpoints held. No best point so far is sent for such a target."},
};
inline constexpr MessageNotes kNotes{&kMessage, "RUNTIME",
                                     "Target position z; commits the target to inverse kinematics. Bits 35 to 39 are "
                                     "reserved: a frame with any of them set is rejected as malformed.",
                                     signal_notes(kSignalNotes)};
}  // namespace target_position_z

// 0x130: compensated tip x, y.
namespace pose_position_xy {
inline constexpr MessageSpec kMessage{
    "POSE_POSITION_XY", 0x130, 1, 8, "RUNTIME", signal_list(position_xy::kSignals), kPoseFrames};
inline constexpr MessageNotes kNotes{&kMessage, "HOST"};
}

// 0x131: tip z, flags, cycle sequence.
namespace pose_position_z {
inline constexpr SignalSpec kZ{"Z", 0, 32, true, kLengthScaleMm, 0, -21474836.48, 21474836.47, "mm"};
// Bit 0: compensated by the GP model (RUN); bit 1: the model extrapolates
// at this pose (see pose_uncertainty); bit 2, in POSE_FD only: its
// POSE_UNCERTAINTY part holds radii; the other bits are 0.
inline constexpr SignalSpec kFlags{"FLAGS", 32, 8, false, 1, 0, 0, 255, ""};
inline constexpr std::int64_t kFlagCompensated = 0x01;
inline constexpr std::int64_t kFlagExtrapolating = 0x02;
inline constexpr std::int64_t kFlagRadii = 0x04;
inline constexpr SignalSpec kSequence{"SEQUENCE", 40, 8, false, 1, 0, 0, 255, ""};
inline constexpr const SignalSpec* kSignals[] = {&kZ, &kFlags, &kSequence};
inline constexpr MessageSpec kMessage{"POSE_POSITION_Z", 0x131, 1, 6, "RUNTIME", signal_list(kSignals), kPoseFrames};
inline constexpr SignalNote kSignalNotes[] = {
    {&kFlags,
     "Bit 0: pose compensated by the GP model (RUN); clear in DEGRADED. Bit 1: the model extrapolates at this pose "
     "(outside the input range it was fitted on, or by its variance; see POSE_UNCERTAINTY). Bit 2, in POSE_FD only: "
     "its POSE_UNCERTAINTY part holds radii (the latest, of the pose its SEQUENCE names). The other bits are 0."},
};
inline constexpr MessageNotes kNotes{&kMessage, "HOST", "", signal_notes(kSignalNotes)};
}  // namespace pose_position_z

// 0x132: compensated tip orientation.
namespace pose_orientation {
inline constexpr MessageSpec kMessage{
    "POSE_ORIENTATION", 0x132, 1, 8, "RUNTIME", signal_list(quaternion::kSignals), kPoseFrames};
inline constexpr MessageNotes kNotes{&kMessage, "HOST"};
}

// 0x133: how far the measured tip may lie from the compensated pose of the
// cycle SEQUENCE (POSE_POSITION_Z's): radii holding it with 95 % probability,
// the model's latent variance there as a share of its prior, and whether
// the model extrapolates. Computed over a few cycles, sent when done.
namespace pose_uncertainty {
inline constexpr SignalSpec kR95Position{"R95_POSITION", 0, 16, false, 0.001, 0, 0, 65.535, "mm"};
inline constexpr SignalSpec kR95Orientation{"R95_ORIENTATION", 16, 16, false, 0.001, 0, 0, 65.535, "deg"};
inline constexpr SignalSpec kLatentShare{"LATENT_SHARE", 32, 8, false, 0.005, 0, 0, 1, ""};
// Bit 0: extrapolating (latent share above the image's threshold; before
// image 2.6 also outside the fitted input range); bit 1: outside the fitted
// input range.
inline constexpr SignalSpec kFlags{"FLAGS", 40, 8, false, 1, 0, 0, 255, ""};
inline constexpr std::int64_t kFlagExtrapolating = 0x01;
inline constexpr std::int64_t kFlagOutsideRange = 0x02;
inline constexpr SignalSpec kSequence{"SEQUENCE", 48, 8, false, 1, 0, 0, 255, ""};
inline constexpr const SignalSpec* kSignals[] = {&kR95Position, &kR95Orientation, &kLatentShare, &kFlags,
                                                 &kSequence};
inline constexpr MessageSpec kMessage{"POSE_UNCERTAINTY", 0x133, 1, 7, "RUNTIME", signal_list(kSignals), kPoseFrames};
inline constexpr SignalNote kSignalNotes[] = {
    {&kR95Position,
     "Radius around the compensated tip position that holds the measured position with 95 % probability, "
     "measurement noise included; saturates at 65.535 mm."},
    {&kR95Orientation,
     "Angle around the compensated orientation that holds the measured one with 95 % probability; saturates at "
     "65.535 deg."},
    {&kLatentShare,
     "The model's latent variance at this pose as a share of its prior: near 0 inside the training data, 1 far from "
     "it."},
    {&kFlags,
     "Bit 0: extrapolating (LATENT_SHARE above the image's threshold; with an image before 2.6 also outside the "
     "fitted input range). Bit 1: outside the fitted input range. The other bits are 0."},
};
inline constexpr MessageNotes kNotes{
    &kMessage, "HOST",
    "95 % radii around the compensated pose of the cycle SEQUENCE (the POSE_POSITION_Z SEQUENCE it belongs to), "
    "computed over a few cycles and sent when done; only with a model image that carries a variance block.",
    signal_notes(kSignalNotes)};
}  // namespace pose_uncertainty

// 0x140: the outcome of a committed target. Bits 12..15 are reserved (0).
namespace ik_report {
inline constexpr SignalSpec kSequence{"SEQUENCE", 0, 8, false, 1, 0, 0, 255, ""};
inline constexpr SignalSpec kOutcome{"OUTCOME", 8, 4, false, 1, 0, 0, 7, "", value_table(values::kIkOutcome)};
inline constexpr SignalSpec kIterations{"ITERATIONS", 16, 8, false, 1, 0, 0, 255, ""};
inline constexpr SignalSpec kCycles{"CYCLES", 24, 8, false, 1, 0, 0, 255, ""};
inline constexpr SignalSpec kPositionResidual{"POSITION_RESIDUAL", 32, 16, false, 0.001, 0, 0, 65.535, "mm"};
inline constexpr SignalSpec kOrientationResidual{"ORIENTATION_RESIDUAL", 48, 16, false, 1e-5, 0, 0, 0.65535, "rad"};
inline constexpr const SignalSpec* kSignals[] = {&kSequence, &kOutcome, &kIterations, &kCycles, &kPositionResidual,
                                                 &kOrientationResidual};
inline constexpr MessageSpec kMessage{"IK_REPORT", 0x140, 1, 8, "RUNTIME", signal_list(kSignals), kIkReportFrames};
inline constexpr SignalNote kSignalNotes[] = {
    {&kIterations, "Solver iterations spent on the target, saturating at 255."},
    {&kCycles, "Runtime cycles spent on the target, saturating at 255."},
    {&kPositionResidual,
     "Position residual of the solution, saturating at 65.535 mm; infinity and NaN are sent as 65.535."},
    {&kOrientationResidual,
     "Orientation residual of a pose target's solution, saturating at 0.65535 rad; 0 for a position target."},
};
inline constexpr MessageNotes kNotes{&kMessage, "HOST",
                                     "Outcome of a committed target. Bits 12 to 15 are reserved (0).",
                                     signal_notes(kSignalNotes)};
}  // namespace ik_report

// 0x150: heartbeat, every kStatusEveryCycles cycles.
namespace status {
inline constexpr SignalSpec kState{"STATE", 0, 4, false, 1, 0, 0, 3, "", value_table(values::kRuntimeState)};
// 1: the latest pose extrapolates (POSE_POSITION_Z FLAGS bit 1). Bits 6..7
// are reserved (0).
inline constexpr SignalSpec kExtrapolating{"EXTRAPOLATING", 4, 1, false, 1, 0, 0, 1, ""};
// 1: the image models the cables' hysteresis and its state is not yet known
// (since power-up, before enough travel or a HOMING frame): poses are less
// certain and POSE_UNCERTAINTY's radii say by how much. Always 0 without a
// hysteresis block.
inline constexpr SignalSpec kHysteresisUnknown{"HYSTERESIS_UNKNOWN", 5, 1, false, 1, 0, 0, 1, ""};
inline constexpr SignalSpec kFault{"FAULT", 8, 8, false, 1, 0, 0, 255, "", value_table(values::kFaultCode)};
inline constexpr SignalSpec kOverruns{"OVERRUNS", 16, 16, false, 1, 0, 0, 65535, ""};
inline constexpr SignalSpec kExecMax{"EXEC_MAX", 32, 16, false, 1, 0, 0, 65535, "us"};
inline constexpr SignalSpec kExecMean{"EXEC_MEAN", 48, 16, false, 1, 0, 0, 65535, "us"};
inline constexpr const SignalSpec* kSignals[] = {&kState,    &kExtrapolating, &kHysteresisUnknown, &kFault,
                                                 &kOverruns, &kExecMax,       &kExecMean};
inline constexpr MessageSpec kMessage{"STATUS", 0x150, 1, 8, "RUNTIME", signal_list(kSignals), kStatusFrames};
inline constexpr SignalNote kSignalNotes[] = {
    {&kExtrapolating, "1: the latest pose extrapolates (POSE_POSITION_Z FLAGS bit 1)."},
    {&kHysteresisUnknown,
     "1: the model image has a hysteresis block and the cables' hysteresis state is not yet known (after power-up, "
     "until every cable has travelled twice its widest play operator one way, or a HOMING frame): the radii of "
     "POSE_UNCERTAINTY include it. Always 0 without a hysteresis block."},
    {&kFault, "firmware::FaultCode of the active fault."},
};
inline constexpr MessageNotes kNotes{&kMessage, "HOST", "Heartbeat, every 10 cycles. Bits 6 to 7 are reserved (0).",
                                     signal_notes(kSignalNotes)};
}  // namespace status

// 0x151: statistics, with each STATUS.
namespace stats {
inline constexpr SignalSpec kJitterMax{"JITTER_MAX", 0, 16, false, 1, 0, 0, 65535, "us"};
inline constexpr SignalSpec kRejectedFrames{"REJECTED_FRAMES", 16, 16, false, 1, 0, 0, 65535, ""};
inline constexpr SignalSpec kCycleCount{"CYCLE_COUNT", 32, 16, false, 1, 0, 0, 65535, ""};
// Typed by the FAULT of the STATUS frame sent with it (fault_detail.hpp).
inline constexpr SignalSpec kFaultDetail{"FAULT_DETAIL", 48, 8, false, 1, 0, 0, 255, ""};
inline constexpr SignalSpec kStaleEvents{"STALE_EVENTS", 56, 8, false, 1, 0, 0, 255, ""};
inline constexpr const SignalSpec* kSignals[] = {&kJitterMax, &kRejectedFrames, &kCycleCount, &kFaultDetail,
                                                 &kStaleEvents};
inline constexpr MessageSpec kMessage{"STATS", 0x151, 1, 8, "RUNTIME", signal_list(kSignals), kStatusFrames};
inline constexpr SignalNote kSignalNotes[] = {
    {&kFaultDetail,
     "Detail of the FAULT in the STATUS frame sent with this one. FAULT 2 image_invalid: model::ImageStatus (0 ok, 1 "
     "truncated, 2 bad_magic, 3 unsupported_version, 4 bad_header, 5 size_mismatch, 6 misaligned, 7 "
     "checksum_mismatch, 8 unsupported_kind, 9 over_capacity, 10 non_finite_payload, 11 invalid_parameters). FAULT 3 "
     "image_geometry_invalid, 6 cable_lengths_invalid and 8 target_unreachable: model::Status (0 ok, 1 "
     "non_finite_input, 2 invalid_geometry, 3 cable_length_not_positive, 4 cable_difference_out_of_range, 5 "
     "theta_beyond_limit, 6 invalid_segment_count, 7 ik_not_converged, 8 correction_failed). FAULT 13 "
     "drive_silent, 14 drive_fault and 15 drive_refused: the drive's CANopen node id (0: the drives' configuration "
     "as given). Any other FAULT: 0."},
};
inline constexpr MessageNotes kNotes{&kMessage, "HOST", "", signal_notes(kSignalNotes)};
}  // namespace stats

// 0x160: the tip payload the robot carries now, for a model with a payload
// input (model/flash-image-v2.md); until one arrives the image's default is
// used. A frame beyond the signal's range is refused (FAULT payload_invalid)
// and the previous payload stays.
namespace payload {
inline constexpr SignalSpec kPayload{"PAYLOAD", 0, 16, false, 0.001, 0, 0, 50, "kg"};
inline constexpr const SignalSpec* kSignals[] = {&kPayload};
inline constexpr MessageSpec kMessage{"PAYLOAD", 0x160, 1, 2, "HOST", signal_list(kSignals), kPayloadFrames};
inline constexpr MessageNotes kNotes{
    &kMessage, "RUNTIME",
    "The tip payload the robot carries now, for a model image with a payload input; until one arrives the runtime "
    "uses the image's default. A frame beyond [0, 50] kg is refused (FAULT 11 payload_invalid) and the previous "
    "payload stays in use."};
}  // namespace payload

// 0x161: the robot has just completed the homing move (model/hysteresis.hpp:
// every segment bent 0.1 rad towards alpha = 45 deg, then straight) and is
// at home: the cables' hysteresis state is the image's homing state from
// now on, and the next cable feedback is its position. Bits 1..7 reserved.
namespace homing {
inline constexpr SignalSpec kAtHome{"AT_HOME", 0, 1, false, 1, 0, 1, 1, ""};
inline constexpr const SignalSpec* kSignals[] = {&kAtHome};
inline constexpr MessageSpec kMessage{"HOMING", 0x161, 1, 1, "HOST", signal_list(kSignals), kPayloadFrames};
inline constexpr MessageNotes kNotes{
    &kMessage, "RUNTIME",
    "The robot has just completed the homing move (every segment bent 0.1 rad towards alpha = 45 deg, then back "
    "straight) and is at home: the runtime takes the cables' hysteresis state as the image's homing state. AT_HOME "
    "must be 1; a frame that does not decode is refused (FAULT 12 homing_malformed). Without a hysteresis block in "
    "the image it changes nothing. Bits 1 to 7 are reserved (0)."};
}  // namespace homing

// 0x162: a command to the drives behind a hal::Drives backend (CiA 402).
// RECOVER: fault reset and re-enable every drive, and leave FAULT once they
// are all in Operation enabled again; sent while the drives are fine it
// changes nothing, so a repeated frame is harmless.
namespace drives_command {
inline constexpr SignalSpec kCommand{"COMMAND", 0, 8, false, 1, 0, 1, 1, "", value_table(values::kDrivesCommand)};
inline constexpr const SignalSpec* kSignals[] = {&kCommand};
inline constexpr MessageSpec kMessage{"DRIVES_COMMAND", 0x162, 1, 1, "HOST", signal_list(kSignals), kPayloadFrames};
inline constexpr MessageNotes kNotes{
    &kMessage, "RUNTIME",
    "A command to the runtime's CiA 402 drives. COMMAND 1 (recover): fault reset and re-enable every drive; the "
    "runtime leaves FAULT 13 to 15 once all are in Operation enabled again. Sent while the drives are fine it changes "
    "nothing. A frame that does not decode is refused (FAULT 16 drives_command_malformed). Without CiA 402 drives it "
    "changes nothing."};
}  // namespace drives_command

// Model updates (0x170..0x17F; firmware/model_update.hpp): the host writes a
// new model image into the inactive flash slot, in blocks of up to
// kUpdateBlockBytes, each an UPDATE_BLOCK header and its UPDATE_DATA frames.
// The runtime acknowledges cumulatively and grants a window of blocks.
inline constexpr hal::CanFilter kUpdateRequestFrames{0x170, 0x7F8};  // UPDATE_COMMAND, _DIGEST, _BLOCK, _DATA
inline constexpr hal::CanFilter kUpdateReportFrames{0x178, 0x7F8};   // UPDATE_REPORT

inline constexpr int kUpdateBlockBytes = 64;
inline constexpr int kUpdateDataFramesPerBlock = kUpdateBlockBytes / 8;

enum class UpdateCommand : std::uint8_t { start = 1, status = 2, abort = 3, commit = 4, rollback = 5 };

enum class UpdateState : std::uint8_t {
  idle = 0,       // no transfer
  preparing = 1,  // erasing the inactive slot
  receiving = 2,  // blocks are welcome: NEXT_BLOCK and WINDOW say which
  verifying = 3,  // all blocks in flash; hashing and validating before commit
  committed = 4,  // the new image is active
  failed = 5,     // the transfer ended with REASON; the active model is unchanged
};

// Why a frame or a transfer was refused (REASON); the active model keeps
// running in every case.
enum class UpdateReason : std::uint8_t {
  none = 0,
  corrupted = 1,             // a block's CRC does not match its data
  duplicate = 2,             // a block already received
  out_of_order = 3,          // a block beyond the next expected one
  missing_block = 4,         // data frames missing from a block, or commit with blocks missing
  timeout = 5,               // the transfer was left without progress for kUpdateTimeoutCycles
  wrong_geometry = 6,        // the image was trained for another robot geometry
  wrong_segment_count = 7,   // the image has another segment count
  unsupported_version = 8,   // an image format version this runtime does not read
  too_large = 9,             // larger than the inactive slot
  busy = 10,                 // another transfer is in progress (abort it first)
  image_invalid = 11,        // the image does not parse or bind (its CRC, its fields)
  digest_mismatch = 12,      // the SHA-256 of the received bytes is not the announced one
  no_transfer = 13,          // a block or commit without a transfer
  no_rollback_image = 14,    // rollback with no valid image in the other slot
  flash_failed = 15,         // the flash reported an error
  malformed = 16,            // a frame of the protocol that does not decode
};

namespace values {
inline constexpr ValueName kUpdateCommand[] = {
    {1, "start"}, {2, "status"}, {3, "abort"}, {4, "commit"}, {5, "rollback"}};
inline constexpr ValueName kUpdateState[] = {{0, "idle"},      {1, "preparing"}, {2, "receiving"},
                                             {3, "verifying"}, {4, "committed"}, {5, "failed"}};
inline constexpr ValueName kUpdateReason[] = {
    {0, "none"},           {1, "corrupted"},        {2, "duplicate"},
    {3, "out_of_order"},   {4, "missing_block"},    {5, "timeout"},
    {6, "wrong_geometry"}, {7, "wrong_segment_count"}, {8, "unsupported_version"},
    {9, "too_large"},      {10, "busy"},            {11, "image_invalid"},
    {12, "digest_mismatch"}, {13, "no_transfer"},   {14, "no_rollback_image"},
    {15, "flash_failed"},  {16, "malformed"},
};
}  // namespace values

// 0x170: a command. START announces a transfer (or resumes the one in
// flash with the same TRANSFER_ID, size and digest); the eight
// UPDATE_DIGEST frames must precede it. Bits 4..7 are reserved.
namespace update_command {
inline constexpr SignalSpec kCommand{"COMMAND", 0, 4, false, 1, 0, 1, 5, "", value_table(values::kUpdateCommand)};
inline constexpr SignalSpec kTransferId{"TRANSFER_ID", 8, 16, false, 1, 0, 0, 65535, ""};
inline constexpr SignalSpec kImageSize{"IMAGE_SIZE", 24, 24, false, 1, 0, 0, 16777215, "B"};
inline constexpr const SignalSpec* kSignals[] = {&kCommand, &kTransferId, &kImageSize};
inline constexpr MessageSpec kMessage{"UPDATE_COMMAND", 0x170, 1, 6, "HOST", signal_list(kSignals),
                                      kUpdateRequestFrames};
inline constexpr MessageNotes kNotes{
    &kMessage, "RUNTIME",
    "Model update command. START announces a transfer of IMAGE_SIZE bytes into the inactive slot, or resumes the one "
    "in flash with the same TRANSFER_ID, size and digest; the eight UPDATE_DIGEST frames precede it. STATUS asks for "
    "an UPDATE_REPORT, ABORT drops the transfer, COMMIT verifies the received image and makes it active, ROLLBACK "
    "makes the other slot's image active again. Bits 4 to 7 are reserved (0)."};
}  // namespace update_command

// 0x171: bytes 4 * PART .. 4 * PART + 3 of the image's SHA-256, in order
// (WORD little-endian). Bits 3..7 are reserved.
namespace update_digest {
inline constexpr SignalSpec kPart{"PART", 0, 3, false, 1, 0, 0, 7, ""};
inline constexpr SignalSpec kWord{"WORD", 8, 32, false, 1, 0, 0, 4294967295.0, ""};
inline constexpr const SignalSpec* kSignals[] = {&kPart, &kWord};
inline constexpr MessageSpec kMessage{"UPDATE_DIGEST", 0x171, 1, 5, "HOST", signal_list(kSignals),
                                      kUpdateRequestFrames};
inline constexpr MessageNotes kNotes{&kMessage, "RUNTIME",
                                     "Bytes 4 * PART to 4 * PART + 3 of the SHA-256 of the image to transfer; WORD "
                                     "little-endian. Bits 3 to 7 are reserved (0)."};
}  // namespace update_digest

// 0x172: the header of block BLOCK (image bytes 64 * BLOCK ..): its length
// and the CRC-32 of its two BLOCK bytes (little-endian) then its data.
namespace update_block {
inline constexpr SignalSpec kBlock{"BLOCK", 0, 16, false, 1, 0, 0, 65535, ""};
inline constexpr SignalSpec kLength{"LENGTH", 16, 8, false, 1, 0, 1, kUpdateBlockBytes, "B"};
inline constexpr SignalSpec kCrc{"CRC", 24, 32, false, 1, 0, 0, 4294967295.0, ""};
inline constexpr const SignalSpec* kSignals[] = {&kBlock, &kLength, &kCrc};
inline constexpr MessageSpec kMessage{"UPDATE_BLOCK", 0x172, 1, 7, "HOST", signal_list(kSignals),
                                      kUpdateRequestFrames};
inline constexpr MessageNotes kNotes{
    &kMessage, "RUNTIME",
    "Header of image block BLOCK (bytes 64 * BLOCK onwards): LENGTH bytes follow in UPDATE_DATA frames, CRC is the "
    "CRC-32 of the two BLOCK bytes (little-endian) followed by the data."};
}  // namespace update_block

// 0x173: the next 8 bytes of the block whose header came last (the last
// frame of a block is zero-padded).
namespace update_data {
inline constexpr SignalSpec kDataLow{"DATA_LOW", 0, 32, false, 1, 0, 0, 4294967295.0, ""};
inline constexpr SignalSpec kDataHigh{"DATA_HIGH", 32, 32, false, 1, 0, 0, 4294967295.0, ""};
inline constexpr const SignalSpec* kSignals[] = {&kDataLow, &kDataHigh};
inline constexpr MessageSpec kMessage{"UPDATE_DATA", 0x173, 1, 8, "HOST", signal_list(kSignals),
                                      kUpdateRequestFrames};
inline constexpr MessageNotes kNotes{
    &kMessage, "RUNTIME", "The next 8 bytes of the block announced last; the last frame of a block is zero-padded."};
}  // namespace update_data

// 0x178: the update's state, the answer to every command and the
// acknowledgement of blocks: blocks 0 .. NEXT_BLOCK - 1 are in flash, and
// the host may send up to WINDOW blocks from NEXT_BLOCK on.
namespace update_report {
inline constexpr SignalSpec kState{"STATE", 0, 4, false, 1, 0, 0, 5, "", value_table(values::kUpdateState)};
// 0: the image of ModelStorage (no slot), 1: slot A, 2: slot B.
inline constexpr SignalSpec kActiveSlot{"ACTIVE_SLOT", 4, 2, false, 1, 0, 0, 2, ""};
inline constexpr SignalSpec kReason{"REASON", 8, 8, false, 1, 0, 0, 16, "", value_table(values::kUpdateReason)};
inline constexpr SignalSpec kNextBlock{"NEXT_BLOCK", 16, 16, false, 1, 0, 0, 65535, ""};
inline constexpr SignalSpec kWindow{"WINDOW", 32, 8, false, 1, 0, 0, 255, ""};
inline constexpr SignalSpec kTransferId{"TRANSFER_ID", 40, 16, false, 1, 0, 0, 65535, ""};
inline constexpr SignalSpec kActiveSequence{"ACTIVE_SEQUENCE", 56, 8, false, 1, 0, 0, 255, ""};
inline constexpr const SignalSpec* kSignals[] = {&kState,  &kActiveSlot,  &kReason,         &kNextBlock,
                                                 &kWindow, &kTransferId, &kActiveSequence};
inline constexpr MessageSpec kMessage{"UPDATE_REPORT", 0x178, 1, 8, "RUNTIME", signal_list(kSignals),
                                      kUpdateReportFrames};
inline constexpr SignalNote kSignalNotes[] = {
    {&kActiveSlot, "The slot the running model is read from: 0 the model storage (no slot), 1 slot A, 2 slot B."},
    {&kActiveSequence, "Low 8 bits of the active slot's sequence number; the higher valid sequence wins at boot."},
};
inline constexpr MessageNotes kNotes{
    &kMessage, "HOST",
    "State of the model update, sent for every command, every acknowledged window and every rejected frame. Blocks 0 "
    "to NEXT_BLOCK - 1 are in flash; the host may send WINDOW blocks from NEXT_BLOCK on.",
    signal_notes(kSignalNotes)};
}  // namespace update_report

// CAN FD messages (message_codec.hpp, FdMessageSpec): on a bus configured
// for CAN FD the runtime sends every frame as an FD frame, and these carry
// in one frame what takes several classical frames. Each part is laid out
// as its classical message, in its own 8 bytes.

// 0x118 + g: the commanded cable lengths of segments 4g to 4g + 3, from the
// runtime, replacing CABLE_SETPOINT_s on an FD bus: one frame for a robot
// of up to four segments. A segment the robot lacks has every length 65535.
namespace cable_setpoints_fd {
inline constexpr int kSegmentsPerFrame = 4;
inline constexpr MessagePart kParts[] = {
    {&cable_setpoint::kMessage, 0}, {&cable_setpoint::kMessage, 1}, {&cable_setpoint::kMessage, 2},
    {&cable_setpoint::kMessage, 3}};
inline constexpr int kFrames = kSegmentIdSlots / kSegmentsPerFrame;
inline constexpr FdMessageSpec kMessage =
    fd_message("CABLE_SETPOINTS_FD", 0x118, kFrames, "RUNTIME", kParts, kCableSetpointsFdFrames);
inline constexpr FdMessageNotes kNotes{
    &kMessage, "DRIVES",
    "CAN FD: the commanded cable lengths of four segments, from segment 4 x the frame's index on, each as its "
    "CABLE_SETPOINT frame; sent instead of CABLE_SETPOINT on an FD bus. A segment the robot lacks has every length "
    "65535."};
}  // namespace cable_setpoints_fd

// 0x123: a whole target in one frame, as its three classical frames would
// carry it: orientation, position x, y, and position z (which commits).
namespace target_fd {
inline constexpr MessagePart kParts[] = {
    {&target_orientation::kMessage}, {&target_position_xy::kMessage}, {&target_position_z::kMessage}};
inline constexpr FdMessageSpec kMessage = fd_message("TARGET_FD", 0x123, 1, "HOST", kParts, kTargetFrames);
inline constexpr FdMessageNotes kNotes{
    &kMessage, "RUNTIME",
    "CAN FD: a whole target, committed: the TARGET_ORIENTATION, TARGET_POSITION_XY and TARGET_POSITION_Z frames in "
    "one (the orientation part is read for MODE = 1 only)."};
}  // namespace target_fd

// 0x134: the pose, its flags and the latest radii in one frame.
namespace pose_fd {
inline constexpr MessagePart kParts[] = {{&pose_position_xy::kMessage},
                                         {&pose_position_z::kMessage},
                                         {&pose_orientation::kMessage},
                                         {&pose_uncertainty::kMessage}};
inline constexpr FdMessageSpec kMessage = fd_message("POSE_FD", 0x134, 1, "RUNTIME", kParts, kPoseFrames);
inline constexpr FdMessageNotes kNotes{
    &kMessage, "HOST",
    "CAN FD: the compensated pose, sent instead of POSE_POSITION_XY, POSE_POSITION_Z, POSE_ORIENTATION and "
    "POSE_UNCERTAINTY on an FD bus. The POSE_UNCERTAINTY part holds the latest radii (its SEQUENCE names their "
    "pose) when POSE_POSITION_Z FLAGS bit 2 is set, and is 0 before the first radii."};
}  // namespace pose_fd

// The FD messages, as the FD DBC lists them after the classical ones.
inline constexpr const FdMessageNotes* kFdMessageNotes[] = {&cable_setpoints_fd::kNotes, &target_fd::kNotes,
                                                           &pose_fd::kNotes};
inline constexpr const FdMessageSpec* kFdMessages[] = {&cable_setpoints_fd::kMessage, &target_fd::kMessage,
                                                      &pose_fd::kMessage};

// Every message of the protocol with its notes, as the DBC lists them.
inline constexpr const MessageNotes* kMessageNotes[] = {
    &cable_feedback::kNotes,     &cable_setpoint::kNotes,   &target_orientation::kNotes,
    &target_position_xy::kNotes, &target_position_z::kNotes, &pose_position_xy::kNotes,
    &pose_position_z::kNotes,    &pose_orientation::kNotes, &pose_uncertainty::kNotes,
    &ik_report::kNotes,          &status::kNotes,           &stats::kNotes,
    &payload::kNotes,            &homing::kNotes,           &drives_command::kNotes,
    &update_command::kNotes,     &update_digest::kNotes,    &update_block::kNotes,
    &update_data::kNotes,        &update_report::kNotes,
};

// Every message of the protocol, in the same order.
inline constexpr auto kMessages = messages_of(kMessageNotes);

constexpr bool all_within_id_window() {
  for (const MessageSpec* m : kMessages) {
    if (m->id < kDefaultIdBase || m->id + m->id_count > kDefaultIdBase + kIdWindow) return false;
  }
  return true;
}
constexpr bool fd_messages_fit() {
  for (const FdMessageSpec* m : kFdMessages) {
    if (m->id < kDefaultIdBase || m->id + m->id_count > kDefaultIdBase + kIdWindow) return false;
    if (!hal::is_fd_length(m->length) || m->length > hal::kMaxFdDataBytes) return false;
    for (int k = 0; k < m->part_count; ++k) {
      if (m->parts[k].message->dlc > kPartBytes) return false;
    }
  }
  return true;
}
static_assert(all_within_id_window(), "every identifier within the window a base moves");
static_assert(fd_messages_fit(), "every FD message within the window, at an FD length, its parts 8 bytes each");
static_assert(cable_setpoints_fd::kFrames * cable_setpoints_fd::kSegmentsPerFrame >= kSegmentIdSlots,
              "the FD setpoint frames cover every segment slot");

}  // namespace cdcr::firmware::protocol
