#pragma once
// Every message and signal of the runtime's CAN protocol, once: identifiers,
// DLC, sender, each signal's bits, scaling, range and unit, the value tables
// of the enums, and the acceptance filter of each frame group.
// firmware/protocol/cdcr.dbc describes the same for candump/cantools users; a
// host test (host_tests/firmware/protocol_test.cpp) checks that both agree,
// field by field, in both directions. frames.hpp encodes and decodes the
// messages from this table.

#include <cstdint>

#include "cdcr/firmware/fault.hpp"
#include "cdcr/firmware/protocol/message_codec.hpp"
#include "cdcr/firmware/protocol/signal_codec.hpp"
#include "cdcr/hal/can_bus.hpp"

namespace cdcr::firmware::protocol {

// Per-segment messages reserve this many identifiers (base .. base + 7).
inline constexpr int kSegmentIdSlots = 8;

// Frame groups, one acceptance filter each: the filter passes every message
// of its group and no other message of the protocol (a test checks it).
inline constexpr hal::CanFilter kCableFeedbackFrames{0x100, 0x7F8};  // CABLE_FEEDBACK_0..7
inline constexpr hal::CanFilter kCableSetpointFrames{0x110, 0x7F8};  // CABLE_SETPOINT_0..7
inline constexpr hal::CanFilter kTargetFrames{0x120, 0x7FC};         // TARGET_ORIENTATION, _POSITION_XY, _POSITION_Z
inline constexpr hal::CanFilter kPoseFrames{0x130, 0x7FC};           // POSE_POSITION_XY, _POSITION_Z, POSE_ORIENTATION
inline constexpr hal::CanFilter kIkReportFrames{0x140, 0x7FF};       // IK_REPORT
inline constexpr hal::CanFilter kStatusFrames{0x150, 0x7FE};         // STATUS, STATS
inline constexpr hal::CanFilter kPayloadFrames{0x160, 0x7FF};        // PAYLOAD

enum class TargetMode : std::uint8_t { position = 0, pose = 1 };

enum class IkOutcome : std::uint8_t {
  converged = 0,           // setpoints published
  unreachable = 1,         // no acceptable solution; setpoints held (STATS FAULT_DETAIL: model::Status)
  rejected_malformed = 2,  // the target frames were inconsistent; setpoints held
  rejected_state = 3,      // the runtime is in FAULT or BOOT; setpoints held
  superseded = 4,          // a newer target replaced this one before it finished
  aborted_fault = 5,       // the runtime entered FAULT while solving
  in_progress = 6,         // periodic report while a solve runs
};

// Scalings. u16 at 0.01 mm spans 0..655.34 mm for cables, several times the
// longest cable of the prototype (L + r * theta_max ~ 225 mm); raw 0xFFFF
// means "not available". i32 at 0.01 mm spans +-21 km: positions never
// saturate. Quaternions (Hamilton, w first) in Q15 with 1.0 = 32767.
inline constexpr double kLengthScaleMm = 0.01;
inline constexpr double kQuaternionScale = 1.0 / 32767.0;
inline constexpr std::int64_t kCableNotAvailableRaw = 0xFFFF;
// A received quaternion must have a norm within this of 1 (Q15 rounding
// moves it by at most ~1e-4).
inline constexpr double kQuaternionNormTolerance = 1e-2;

namespace values {
inline constexpr ValueName kTargetMode[] = {{0, "position"}, {1, "pose"}};
inline constexpr ValueName kIkOutcome[] = {
    {0, "converged"},     {1, "unreachable"},   {2, "rejected_malformed"}, {3, "rejected_state"},
    {4, "superseded"},    {5, "aborted_fault"}, {6, "in_progress"},
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
};
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
}

// 0x110 + s: commanded cable lengths of segment s.
namespace cable_setpoint {
inline constexpr MessageSpec kMessage{
    "CABLE_SETPOINT", 0x110, kSegmentIdSlots, 8, "RUNTIME", signal_list(cable_lengths::kSignals), kCableSetpointFrames};
}

// 0x120: target orientation, before the commit frame of a pose target.
namespace target_orientation {
inline constexpr MessageSpec kMessage{
    "TARGET_ORIENTATION", 0x120, 1, 8, "HOST", signal_list(quaternion::kSignals), kTargetFrames};
}

// 0x121: target x, y, before the commit frame.
namespace target_position_xy {
inline constexpr MessageSpec kMessage{
    "TARGET_POSITION_XY", 0x121, 1, 8, "HOST", signal_list(position_xy::kSignals), kTargetFrames};
}

// 0x122: target z; commits the target. Bits 34..39 are reserved and must be 0.
namespace target_position_z {
inline constexpr SignalSpec kZ{"Z", 0, 32, true, kLengthScaleMm, 0, -21474836.48, 21474836.47, "mm"};
inline constexpr SignalSpec kMode{"MODE", 32, 1, false, 1, 0, 0, 1, "", value_table(values::kTargetMode)};
// 1: one target of a stream along a path; the solver warm-starts from its
// last solution and may publish the best point so far.
inline constexpr SignalSpec kTracking{"TRACKING", 33, 1, false, 1, 0, 0, 1, ""};
inline constexpr SignalSpec kSequence{"SEQUENCE", 40, 8, false, 1, 0, 0, 255, ""};
inline constexpr const SignalSpec* kSignals[] = {&kZ, &kMode, &kTracking, &kSequence};
inline constexpr MessageSpec kMessage{"TARGET_POSITION_Z", 0x122, 1, 6, "HOST", signal_list(kSignals), kTargetFrames};
}  // namespace target_position_z

// 0x130: compensated tip x, y.
namespace pose_position_xy {
inline constexpr MessageSpec kMessage{
    "POSE_POSITION_XY", 0x130, 1, 8, "RUNTIME", signal_list(position_xy::kSignals), kPoseFrames};
}

// 0x131: tip z, flags, cycle sequence.
namespace pose_position_z {
inline constexpr SignalSpec kZ{"Z", 0, 32, true, kLengthScaleMm, 0, -21474836.48, 21474836.47, "mm"};
// Bit 0: compensated by the GP model (RUN); bit 1: the model extrapolates
// at this pose (see pose_uncertainty); the other bits are 0.
inline constexpr SignalSpec kFlags{"FLAGS", 32, 8, false, 1, 0, 0, 255, ""};
inline constexpr std::int64_t kFlagCompensated = 0x01;
inline constexpr std::int64_t kFlagExtrapolating = 0x02;
inline constexpr SignalSpec kSequence{"SEQUENCE", 40, 8, false, 1, 0, 0, 255, ""};
inline constexpr const SignalSpec* kSignals[] = {&kZ, &kFlags, &kSequence};
inline constexpr MessageSpec kMessage{"POSE_POSITION_Z", 0x131, 1, 6, "RUNTIME", signal_list(kSignals), kPoseFrames};
}  // namespace pose_position_z

// 0x132: compensated tip orientation.
namespace pose_orientation {
inline constexpr MessageSpec kMessage{
    "POSE_ORIENTATION", 0x132, 1, 8, "RUNTIME", signal_list(quaternion::kSignals), kPoseFrames};
}

// 0x133: how far the measured tip may lie from the compensated pose of the
// cycle SEQUENCE (POSE_POSITION_Z's): radii holding it with 95 % probability,
// the model's latent variance there as a share of its prior, and whether
// the model extrapolates. Computed over a few cycles, sent when done.
namespace pose_uncertainty {
inline constexpr SignalSpec kR95Position{"R95_POSITION", 0, 16, false, 0.001, 0, 0, 65.535, "mm"};
inline constexpr SignalSpec kR95Orientation{"R95_ORIENTATION", 16, 16, false, 0.001, 0, 0, 65.535, "deg"};
inline constexpr SignalSpec kLatentShare{"LATENT_SHARE", 32, 8, false, 0.005, 0, 0, 1, ""};
// Bit 0: extrapolating (outside the fitted input range, or latent share
// above the image's threshold); bit 1: outside the fitted input range.
inline constexpr SignalSpec kFlags{"FLAGS", 40, 8, false, 1, 0, 0, 255, ""};
inline constexpr std::int64_t kFlagExtrapolating = 0x01;
inline constexpr std::int64_t kFlagOutsideRange = 0x02;
inline constexpr SignalSpec kSequence{"SEQUENCE", 48, 8, false, 1, 0, 0, 255, ""};
inline constexpr const SignalSpec* kSignals[] = {&kR95Position, &kR95Orientation, &kLatentShare, &kFlags,
                                                 &kSequence};
inline constexpr MessageSpec kMessage{"POSE_UNCERTAINTY", 0x133, 1, 7, "RUNTIME", signal_list(kSignals), kPoseFrames};
}  // namespace pose_uncertainty

// 0x140: the outcome of a committed target. Bits 12..15 are reserved (0).
namespace ik_report {
inline constexpr SignalSpec kSequence{"SEQUENCE", 0, 8, false, 1, 0, 0, 255, ""};
inline constexpr SignalSpec kOutcome{"OUTCOME", 8, 4, false, 1, 0, 0, 6, "", value_table(values::kIkOutcome)};
inline constexpr SignalSpec kIterations{"ITERATIONS", 16, 8, false, 1, 0, 0, 255, ""};
inline constexpr SignalSpec kCycles{"CYCLES", 24, 8, false, 1, 0, 0, 255, ""};
inline constexpr SignalSpec kPositionResidual{"POSITION_RESIDUAL", 32, 16, false, 0.001, 0, 0, 65.535, "mm"};
inline constexpr SignalSpec kOrientationResidual{"ORIENTATION_RESIDUAL", 48, 16, false, 1e-5, 0, 0, 0.65535, "rad"};
inline constexpr const SignalSpec* kSignals[] = {&kSequence, &kOutcome, &kIterations, &kCycles, &kPositionResidual,
                                                 &kOrientationResidual};
inline constexpr MessageSpec kMessage{"IK_REPORT", 0x140, 1, 8, "RUNTIME", signal_list(kSignals), kIkReportFrames};
}  // namespace ik_report

// 0x150: heartbeat, every kStatusEveryCycles cycles.
namespace status {
inline constexpr SignalSpec kState{"STATE", 0, 4, false, 1, 0, 0, 3, "", value_table(values::kRuntimeState)};
// 1: the latest pose extrapolates (POSE_POSITION_Z FLAGS bit 1). Bits 5..7
// are reserved (0).
inline constexpr SignalSpec kExtrapolating{"EXTRAPOLATING", 4, 1, false, 1, 0, 0, 1, ""};
inline constexpr SignalSpec kFault{"FAULT", 8, 8, false, 1, 0, 0, 255, "", value_table(values::kFaultCode)};
inline constexpr SignalSpec kOverruns{"OVERRUNS", 16, 16, false, 1, 0, 0, 65535, ""};
inline constexpr SignalSpec kExecMax{"EXEC_MAX", 32, 16, false, 1, 0, 0, 65535, "us"};
inline constexpr SignalSpec kExecMean{"EXEC_MEAN", 48, 16, false, 1, 0, 0, 65535, "us"};
inline constexpr const SignalSpec* kSignals[] = {&kState, &kExtrapolating, &kFault, &kOverruns, &kExecMax, &kExecMean};
inline constexpr MessageSpec kMessage{"STATUS", 0x150, 1, 8, "RUNTIME", signal_list(kSignals), kStatusFrames};
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
}  // namespace stats

// 0x160: the tip payload the robot carries now, for a model with a payload
// input (model/flash-image-v2.md); until one arrives the image's default is
// used. A frame beyond the signal's range is refused (FAULT payload_invalid)
// and the previous payload stays.
namespace payload {
inline constexpr SignalSpec kPayload{"PAYLOAD", 0, 16, false, 0.001, 0, 0, 50, "kg"};
inline constexpr const SignalSpec* kSignals[] = {&kPayload};
inline constexpr MessageSpec kMessage{"PAYLOAD", 0x160, 1, 2, "HOST", signal_list(kSignals), kPayloadFrames};
}  // namespace payload

// Every message of the protocol, as the DBC lists them.
inline constexpr const MessageSpec* kMessages[] = {
    &cable_feedback::kMessage,     &cable_setpoint::kMessage,   &target_orientation::kMessage,
    &target_position_xy::kMessage, &target_position_z::kMessage, &pose_position_xy::kMessage,
    &pose_position_z::kMessage,    &pose_orientation::kMessage, &pose_uncertainty::kMessage,
    &ik_report::kMessage,          &status::kMessage,           &stats::kMessage,
    &payload::kMessage,
};

}  // namespace cdcr::firmware::protocol
