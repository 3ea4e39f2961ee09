// A golden frame of every message of the protocol: identifier, DLC and data
// bytes worked out by hand from the protocol's documentation (each signal's
// start bit, length, scale, offset and sign; Intel byte order, frame bit k is
// bit k % 8 of byte k / 8), not from the codec's table. Each golden frame is
// encoded from its typed struct and compared byte for byte, and decoded from
// its bytes and compared field by field.
//
// The DBC file is generated from the table, so the DBC test cannot catch a
// wrong start bit or scale in the table any more; these frames can. When a
// frame on the bus changes on purpose, change its bytes here by hand.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iterator>
#include <string>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/firmware/fault_detail.hpp>
#include <cdcr/firmware/protocol.hpp>
#include <cdcr/hal/shifted_can_bus.hpp>

#include "golden_frames.hpp"

namespace cdcr::firmware::protocol {
namespace {

using test_support::Bytes;
using test_support::frame_of;

// "0x122 [26 9E FF FF 05 5A]", to name the golden frame a failure is about.
std::string golden_name(std::uint32_t id, const Bytes& bytes) {
  char text[8];
  std::snprintf(text, sizeof text, "0x%03X", static_cast<unsigned>(id));
  std::string name = std::string(text) + " [";
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    std::snprintf(text, sizeof text, i == 0 ? "%02X" : " %02X", bytes[i]);
    name += text;
  }
  return name + "]";
}

// Encodes `message` into a frame whose bytes are all 0xAA first, so that a
// byte the encoder forgets to write shows.
template <typename Message>
void expect_encodes_to(const Message& message, std::uint32_t id, const Bytes& bytes) {
  SCOPED_TRACE("encoding golden frame " + golden_name(id, bytes));
  hal::CanFrame frame;
  std::fill(std::begin(frame.data), std::end(frame.data), std::uint8_t{0xAA});
  if constexpr (std::is_same_v<decltype(encode(message, frame)), bool>) {
    ASSERT_TRUE(encode(message, frame)) << "the encoder refused the message";
  } else {
    encode(message, frame);
  }
  EXPECT_EQ(frame.id, id);
  ASSERT_EQ(frame.dlc, bytes.size());
  EXPECT_EQ(Bytes(frame.data, frame.data + frame.dlc), bytes);
}

template <typename Message>
Message decoded(std::uint32_t id, const Bytes& bytes) {
  SCOPED_TRACE("decoding golden frame " + golden_name(id, bytes));
  Message message;
  EXPECT_STREQ(to_string(decode(frame_of(id, bytes), message)), to_string(DecodeStatus::ok));
  return message;
}

// A physical value decodes as raw * scale + offset: the same double up to
// the last bits of the multiplication.
void expect_physical(double actual, double expected) {
  EXPECT_NEAR(actual, expected, 1e-9 * std::max(1.0, std::fabs(expected)));
}

// The four lengths of a CABLE_FEEDBACK_s or CABLE_SETPOINT_s frame decode
// as sent: every golden length is a whole number of 0.01 mm.
template <typename CableFrame>
void expect_cable_golden(const CableFrame& sent, std::uint32_t id, const Bytes& bytes) {
  expect_encodes_to(sent, id, bytes);
  const auto received = decoded<CableFrame>(id, bytes);
  EXPECT_EQ(received.segment, sent.segment);
  for (int k = 0; k < 4; ++k) expect_physical(received.lengths_mm[k], sent.lengths_mm[k]);
}

// CABLE_FEEDBACK_s: 0x100 + s, DLC 8, from the drives; CABLE_SETPOINT_s:
// 0x110 + s, DLC 8, from the runtime. L1..L4: u16 at bits 0, 16, 32, 48,
// 0.01 mm per bit.
TEST(GoldenFrames, CableFeedbackAndSetpoint) {
  // Segment 2: 0x102. 100.00 mm = 10000 = 0x2710; 123.45 mm = 12345 =
  // 0x3039; 0.01 mm = 1; 655.34 mm = 65534 = 0xFFFE.
  expect_cable_golden(CableFeedback{2, {100.0, 123.45, 0.01, 655.34}}, 0x102,
                      Bytes{0x10, 0x27, 0x39, 0x30, 0x01, 0x00, 0xFE, 0xFF});
  // Segment 7: 0x117. 0.5 mm = 50 = 0x0032; 225 mm = 22500 = 0x57E4;
  // 300.01 mm = 30001 = 0x7531; 42.42 mm = 4242 = 0x1092.
  expect_cable_golden(CableSetpoint{7, {0.5, 225.0, 300.01, 42.42}}, 0x117,
                      Bytes{0x32, 0x00, 0xE4, 0x57, 0x31, 0x75, 0x92, 0x10});
}

// 0x120, DLC 8. QW, QX, QY, QZ: i16 at bits 0, 16, 32, 48, Q15 (raw =
// round(value * 32767)).
TEST(GoldenFrames, TargetOrientation) {
  // 0.1 -> 3276.7 -> 3277 = 0x0CCD; 0.7 -> 22937 = 0x5999;
  // -0.1 -> -3277 = 0xF333; -0.7 -> -22937 = 0xA667.
  const Bytes bytes{0xCD, 0x0C, 0x99, 0x59, 0x33, 0xF3, 0x67, 0xA6};
  expect_encodes_to(TargetOrientation{0.1, 0.7, -0.1, -0.7}, 0x120, bytes);
  const auto q = decoded<TargetOrientation>(0x120, bytes);
  expect_physical(q.qw, 3277.0 / 32767);
  expect_physical(q.qx, 22937.0 / 32767);
  expect_physical(q.qy, -3277.0 / 32767);
  expect_physical(q.qz, -22937.0 / 32767);
}

// 0x121, DLC 8. X, Y: i32 at bits 0 and 32, 0.01 mm per bit.
TEST(GoldenFrames, TargetPositionXy) {
  // 123456.78 mm = 12345678 = 0x00BC614E; -98765.43 mm = -9876543 = 0xFF694BC1.
  const Bytes bytes{0x4E, 0x61, 0xBC, 0x00, 0xC1, 0x4B, 0x69, 0xFF};
  expect_encodes_to(TargetPositionXy{123456.78, -98765.43}, 0x121, bytes);
  const auto xy = decoded<TargetPositionXy>(0x121, bytes);
  expect_physical(xy.x_mm, 123456.78);
  expect_physical(xy.y_mm, -98765.43);
}

// 0x122, DLC 6. Z: i32 at bit 0, 0.01 mm; MODE bit 32 (1 = pose); TRACKING
// bit 33; REFUSE_EXTRAPOLATING bit 34; bits 35..39 reserved; SEQUENCE u8 at
// bit 40.
TEST(GoldenFrames, TargetPositionZPoseRefusingExtrapolation) {
  // -250.5 mm = -25050 = 0xFFFF9E26; byte 4 = MODE | REFUSE_EXTRAPOLATING = 0x01 | 0x04.
  const Bytes bytes{0x26, 0x9E, 0xFF, 0xFF, 0x05, 0x5A};
  TargetPositionZ sent{-250.5, TargetMode::pose, false, 0x5A};
  sent.refuse_extrapolating = true;
  expect_encodes_to(sent, 0x122, bytes);
  const auto z = decoded<TargetPositionZ>(0x122, bytes);
  expect_physical(z.z_mm, -250.5);
  EXPECT_EQ(z.mode, TargetMode::pose);
  EXPECT_FALSE(z.tracking);
  EXPECT_TRUE(z.refuse_extrapolating);
  EXPECT_EQ(z.sequence, 0x5A);
}

TEST(GoldenFrames, TargetPositionZTrackingPosition) {
  // 1000.01 mm = 100001 = 0x000186A1; byte 4 = TRACKING = 0x02; SEQUENCE 200 = 0xC8.
  const Bytes bytes{0xA1, 0x86, 0x01, 0x00, 0x02, 0xC8};
  expect_encodes_to(TargetPositionZ{1000.01, TargetMode::position, true, 200}, 0x122, bytes);
  const auto z = decoded<TargetPositionZ>(0x122, bytes);
  expect_physical(z.z_mm, 1000.01);
  EXPECT_EQ(z.mode, TargetMode::position);
  EXPECT_TRUE(z.tracking);
  EXPECT_FALSE(z.refuse_extrapolating);
  EXPECT_EQ(z.sequence, 200);
}

// 0x130, DLC 8: the layout of TARGET_POSITION_XY.
TEST(GoldenFrames, PosePositionXy) {
  // -4321.09 mm = -432109 = 0xFFF96813; 876.54 mm = 87654 = 0x00015666.
  const Bytes bytes{0x13, 0x68, 0xF9, 0xFF, 0x66, 0x56, 0x01, 0x00};
  expect_encodes_to(PosePositionXy{-4321.09, 876.54}, 0x130, bytes);
  const auto xy = decoded<PosePositionXy>(0x130, bytes);
  expect_physical(xy.x_mm, -4321.09);
  expect_physical(xy.y_mm, 876.54);
}

// 0x131, DLC 6. Z: i32 at bit 0, 0.01 mm; FLAGS u8 at bit 32 (bit 0
// compensated, bit 1 extrapolating); SEQUENCE u8 at bit 40.
TEST(GoldenFrames, PosePositionZ) {
  // 187.25 mm = 18725 = 0x4925; FLAGS 0x03; SEQUENCE 0x81.
  const Bytes both{0x25, 0x49, 0x00, 0x00, 0x03, 0x81};
  PosePositionZ sent{187.25, true, 0x81};
  sent.extrapolating = true;
  expect_encodes_to(sent, 0x131, both);
  auto z = decoded<PosePositionZ>(0x131, both);
  expect_physical(z.z_mm, 187.25);
  EXPECT_TRUE(z.compensated);
  EXPECT_TRUE(z.extrapolating);
  EXPECT_EQ(z.sequence, 0x81);

  // -0.01 mm = -1 = 0xFFFFFFFF; FLAGS 0x02: extrapolating, not compensated.
  const Bytes extrapolating{0xFF, 0xFF, 0xFF, 0xFF, 0x02, 0x01};
  sent = PosePositionZ{-0.01, false, 1};
  sent.extrapolating = true;
  expect_encodes_to(sent, 0x131, extrapolating);
  z = decoded<PosePositionZ>(0x131, extrapolating);
  expect_physical(z.z_mm, -0.01);
  EXPECT_FALSE(z.compensated);
  EXPECT_TRUE(z.extrapolating);
  EXPECT_EQ(z.sequence, 1);
}

// 0x132, DLC 8: the layout of TARGET_ORIENTATION.
TEST(GoldenFrames, PoseOrientation) {
  // 0.8 -> 26213.6 -> 26214 = 0x6666; -0.4 -> -13107 = 0xCCCD;
  // 0.2 -> 6553.4 -> 6553 = 0x1999; 0.4 -> 13107 = 0x3333.
  const Bytes bytes{0x66, 0x66, 0xCD, 0xCC, 0x99, 0x19, 0x33, 0x33};
  expect_encodes_to(PoseOrientation{0.8, -0.4, 0.2, 0.4}, 0x132, bytes);
  const auto q = decoded<PoseOrientation>(0x132, bytes);
  expect_physical(q.qw, 26214.0 / 32767);
  expect_physical(q.qx, -13107.0 / 32767);
  expect_physical(q.qy, 6553.0 / 32767);
  expect_physical(q.qz, 13107.0 / 32767);
}

// 0x133, DLC 7. R95_POSITION u16 at bit 0, 0.001 mm; R95_ORIENTATION u16 at
// bit 16, 0.001 deg; LATENT_SHARE u8 at bit 32, 0.005; FLAGS u8 at bit 40
// (bit 0 extrapolating, bit 1 outside the fitted range); SEQUENCE u8 at bit 48.
TEST(GoldenFrames, PoseUncertainty) {
  // 2.5 mm = 2500 = 0x09C4; 12.345 deg = 12345 = 0x3039; 0.35 = 70 = 0x46;
  // FLAGS 0x02 (outside the range only); SEQUENCE 0xEE.
  const Bytes outside{0xC4, 0x09, 0x39, 0x30, 0x46, 0x02, 0xEE};
  PoseUncertainty sent;
  sent.r95_position_mm = 2.5;
  sent.r95_orientation_deg = 12.345;
  sent.latent_share = 0.35;
  sent.extrapolating = false;
  sent.outside_range = true;
  sent.sequence = 0xEE;
  expect_encodes_to(sent, 0x133, outside);
  auto u = decoded<PoseUncertainty>(0x133, outside);
  expect_physical(u.r95_position_mm, 2.5);
  expect_physical(u.r95_orientation_deg, 12.345);
  expect_physical(u.latent_share, 0.35);
  EXPECT_FALSE(u.extrapolating);
  EXPECT_TRUE(u.outside_range);
  EXPECT_EQ(u.sequence, 0xEE);

  // 0.001 mm = 1; 65.535 deg = 65535 = 0xFFFF; 1.0 = 200 = 0xC8; FLAGS 0x01.
  const Bytes extrapolating{0x01, 0x00, 0xFF, 0xFF, 0xC8, 0x01, 0x03};
  sent.r95_position_mm = 0.001;
  sent.r95_orientation_deg = 65.535;
  sent.latent_share = 1.0;
  sent.extrapolating = true;
  sent.outside_range = false;
  sent.sequence = 3;
  expect_encodes_to(sent, 0x133, extrapolating);
  u = decoded<PoseUncertainty>(0x133, extrapolating);
  expect_physical(u.r95_position_mm, 0.001);
  expect_physical(u.r95_orientation_deg, 65.535);
  expect_physical(u.latent_share, 1.0);
  EXPECT_TRUE(u.extrapolating);
  EXPECT_FALSE(u.outside_range);
  EXPECT_EQ(u.sequence, 3);
}

// 0x140, DLC 8. SEQUENCE u8 at bit 0; OUTCOME u4 at bit 8 (bits 12..15
// reserved); ITERATIONS u8 at bit 16; CYCLES u8 at bit 24; POSITION_RESIDUAL
// u16 at bit 32, 0.001 mm; ORIENTATION_RESIDUAL u16 at bit 48, 0.00001 rad.
TEST(GoldenFrames, IkReport) {
  // OUTCOME 7 refused_extrapolating; 37 iterations = 0x25; 9 cycles;
  // 0.123 mm = 123 = 0x007B; 0.01234 rad = 1234 = 0x04D2.
  const Bytes bytes{0x42, 0x07, 0x25, 0x09, 0x7B, 0x00, 0xD2, 0x04};
  expect_encodes_to(IkReport{0x42, IkOutcome::refused_extrapolating, 37, 9, 0.123, 0.01234}, 0x140, bytes);
  const auto report = decoded<IkReport>(0x140, bytes);
  EXPECT_EQ(report.sequence, 0x42);
  EXPECT_EQ(report.outcome, IkOutcome::refused_extrapolating);
  EXPECT_EQ(report.iterations, 37);
  EXPECT_EQ(report.cycles, 9);
  expect_physical(report.position_residual_mm, 0.123);
  expect_physical(report.orientation_residual_rad, 0.01234);
}

// 0x150, DLC 8. STATE u4 at bit 0; EXTRAPOLATING bit 4; HYSTERESIS_UNKNOWN
// bit 5 (6..7 reserved);
// FAULT u8 at bit 8; OVERRUNS u16 at bit 16; EXEC_MAX u16 at bit 32, us;
// EXEC_MEAN u16 at bit 48, us.
TEST(GoldenFrames, Status) {
  // STATE 3 FAULT | EXTRAPOLATING 0x10; FAULT 8 target_unreachable;
  // 513 overruns = 0x0201; 1500 us = 0x05DC; 750 us = 0x02EE.
  const Bytes bytes{0x13, 0x08, 0x01, 0x02, 0xDC, 0x05, 0xEE, 0x02};
  Status sent{RuntimeState::fault, FaultCode::target_unreachable, 513, 1500, 750};
  sent.extrapolating = true;
  expect_encodes_to(sent, 0x150, bytes);
  const auto status = decoded<Status>(0x150, bytes);
  EXPECT_EQ(status.state, RuntimeState::fault);
  EXPECT_TRUE(status.extrapolating);
  EXPECT_EQ(status.fault, FaultCode::target_unreachable);
  EXPECT_EQ(status.overruns, 513);
  EXPECT_EQ(status.exec_max_us, 1500);
  EXPECT_EQ(status.exec_mean_us, 750);
  EXPECT_FALSE(status.hysteresis_unknown);

  // STATE 1 RUN | HYSTERESIS_UNKNOWN 0x20; FAULT 0; 0 overruns; 7 us; 3 us.
  const Bytes unknown{0x21, 0x00, 0x00, 0x00, 0x07, 0x00, 0x03, 0x00};
  Status running{RuntimeState::run, FaultCode::none, 0, 7, 3};
  running.hysteresis_unknown = true;
  expect_encodes_to(running, 0x150, unknown);
  const auto decoded_unknown = decoded<Status>(0x150, unknown);
  EXPECT_TRUE(decoded_unknown.hysteresis_unknown);
  EXPECT_FALSE(decoded_unknown.extrapolating);
  EXPECT_EQ(decoded_unknown.state, RuntimeState::run);
  // Bits 6 and 7 are still reserved.
  Status reserved;
  EXPECT_EQ(decode(frame_of(0x150, Bytes{0x61, 0x00, 0x00, 0x00, 0x07, 0x00, 0x03, 0x00}), reserved),
            DecodeStatus::reserved_bits_set);
}

// 0x151, DLC 8. JITTER_MAX u16 at bit 0, us; REJECTED_FRAMES u16 at bit 16;
// CYCLE_COUNT u16 at bit 32; FAULT_DETAIL u8 at bit 48; STALE_EVENTS u8 at
// bit 56.
TEST(GoldenFrames, Stats) {
  // 25 us = 0x0019; 4660 = 0x1234; 0xBEEF; checksum_mismatch = 7; 12 = 0x0C.
  const Bytes bytes{0x19, 0x00, 0x34, 0x12, 0xEF, 0xBE, 0x07, 0x0C};
  expect_encodes_to(Stats{25, 4660, 0xBEEF, FaultDetail(model::ImageStatus::checksum_mismatch), 12}, 0x151, bytes);
  Stats stats;
  ASSERT_STREQ(to_string(decode(frame_of(0x151, bytes), FaultCode::image_invalid, stats)),
               to_string(DecodeStatus::ok));
  EXPECT_EQ(stats.jitter_max_us, 25);
  EXPECT_EQ(stats.rejected_frames, 4660);
  EXPECT_EQ(stats.cycle_count, 0xBEEF);
  EXPECT_EQ(stats.fault_detail, FaultDetail(model::ImageStatus::checksum_mismatch));
  EXPECT_EQ(stats.stale_events, 12);
}

// 0x160, DLC 2. PAYLOAD u16 at bit 0, 0.001 kg.
TEST(GoldenFrames, Payload) {
  // 12.345 kg = 12345 = 0x3039; 0.75 kg = 750 = 0x02EE.
  expect_encodes_to(Payload{12.345}, 0x160, Bytes{0x39, 0x30});
  expect_physical(decoded<Payload>(0x160, Bytes{0x39, 0x30}).payload_kg, 12.345);
  expect_encodes_to(Payload{0.75}, 0x160, Bytes{0xEE, 0x02});
  expect_physical(decoded<Payload>(0x160, Bytes{0xEE, 0x02}).payload_kg, 0.75);
}

// 0x161, DLC 1. AT_HOME bit 0, must be 1 (1..7 reserved).
TEST(GoldenFrames, Homing) {
  expect_encodes_to(Homing{}, 0x161, Bytes{0x01});
  EXPECT_TRUE(decoded<Homing>(0x161, Bytes{0x01}).at_home);
  Homing homing;
  EXPECT_EQ(decode(frame_of(0x161, Bytes{0x00}), homing), DecodeStatus::out_of_range);
  EXPECT_EQ(decode(frame_of(0x161, Bytes{0x03}), homing), DecodeStatus::reserved_bits_set);
  EXPECT_EQ(decode(frame_of(0x161, Bytes{0x01, 0x00}), homing), DecodeStatus::wrong_dlc);
}

// 0x162, DLC 1. COMMAND u8 at bit 0: 1 recover, nothing else.
TEST(GoldenFrames, DrivesCommand) {
  expect_encodes_to(DrivesCommand{}, 0x162, Bytes{0x01});
  EXPECT_EQ(decoded<DrivesCommand>(0x162, Bytes{0x01}).command, DrivesCommandKind::recover);
  DrivesCommand command;
  EXPECT_EQ(decode(frame_of(0x162, Bytes{0x00}), command), DecodeStatus::out_of_range);
  EXPECT_EQ(decode(frame_of(0x162, Bytes{0x02}), command), DecodeStatus::out_of_range);
  EXPECT_EQ(decode(frame_of(0x162, Bytes{0x01, 0x00}), command), DecodeStatus::wrong_dlc);
}

// 0x170, DLC 6. COMMAND u4 at bit 0 (4..7 reserved); TRANSFER_ID u16 at
// bit 8; IMAGE_SIZE u24 at bit 24, bytes.
TEST(GoldenFrames, UpdateCommand) {
  // START = 1; 0xABCD; 74661 B = 0x0123A5.
  const Bytes start{0x01, 0xCD, 0xAB, 0xA5, 0x23, 0x01};
  expect_encodes_to(UpdateCommandFrame{UpdateCommand::start, 0xABCD, 0x0123A5}, 0x170, start);
  auto command = decoded<UpdateCommandFrame>(0x170, start);
  EXPECT_EQ(command.command, UpdateCommand::start);
  EXPECT_EQ(command.transfer_id, 0xABCD);
  EXPECT_EQ(command.image_size, 0x0123A5u);

  // COMMIT = 4.
  const Bytes commit{0x04, 0x07, 0x00, 0x00, 0x00, 0x00};
  expect_encodes_to(UpdateCommandFrame{UpdateCommand::commit, 7, 0}, 0x170, commit);
  command = decoded<UpdateCommandFrame>(0x170, commit);
  EXPECT_EQ(command.command, UpdateCommand::commit);
  EXPECT_EQ(command.transfer_id, 7);
  EXPECT_EQ(command.image_size, 0u);
}

// 0x171, DLC 5. PART u3 at bit 0 (3..7 reserved); WORD u32 at bit 8: the
// digest's bytes 4 * PART .. 4 * PART + 3 in order.
TEST(GoldenFrames, UpdateDigest) {
  const Bytes bytes{0x05, 0xDE, 0xAD, 0xBE, 0xEF};
  expect_encodes_to(UpdateDigest{5, {0xDE, 0xAD, 0xBE, 0xEF}}, 0x171, bytes);
  const auto digest = decoded<UpdateDigest>(0x171, bytes);
  EXPECT_EQ(digest.part, 5);
  EXPECT_EQ(Bytes(digest.bytes, digest.bytes + 4), (Bytes{0xDE, 0xAD, 0xBE, 0xEF}));
}

// 0x172, DLC 7. BLOCK u16 at bit 0; LENGTH u8 at bit 16, bytes; CRC u32 at
// bit 24.
TEST(GoldenFrames, UpdateBlock) {
  // Block 770 = 0x0302; 40 B = 0x28; CRC 0x89ABCDEF.
  const Bytes bytes{0x02, 0x03, 0x28, 0xEF, 0xCD, 0xAB, 0x89};
  expect_encodes_to(UpdateBlock{770, 40, 0x89ABCDEF}, 0x172, bytes);
  const auto block = decoded<UpdateBlock>(0x172, bytes);
  EXPECT_EQ(block.block, 770);
  EXPECT_EQ(block.length, 40);
  EXPECT_EQ(block.crc, 0x89ABCDEFu);
}

// 0x173, DLC 8. DATA_LOW u32 at bit 0, DATA_HIGH u32 at bit 32: the block's
// next 8 bytes in order.
TEST(GoldenFrames, UpdateData) {
  const Bytes bytes{0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88};
  expect_encodes_to(UpdateData{{0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88}}, 0x173, bytes);
  const auto data = decoded<UpdateData>(0x173, bytes);
  EXPECT_EQ(Bytes(data.bytes, data.bytes + 8), bytes);
}

// 0x178, DLC 8. STATE u4 at bit 0; ACTIVE_SLOT u2 at bit 4 (6..7
// reserved); REASON u8 at bit 8; NEXT_BLOCK u16 at bit 16; WINDOW u8 at bit
// 32; TRANSFER_ID u16 at bit 40; ACTIVE_SEQUENCE u8 at bit 56.
TEST(GoldenFrames, UpdateReport) {
  // STATE 5 failed | ACTIVE_SLOT 2 << 4 = 0x25; REASON 12 digest_mismatch;
  // block 912 = 0x0390; WINDOW 16; 0xBEEF; sequence 0x7E.
  const Bytes bytes{0x25, 0x0C, 0x90, 0x03, 0x10, 0xEF, 0xBE, 0x7E};
  expect_encodes_to(UpdateReport{UpdateState::failed, 2, UpdateReason::digest_mismatch, 912, 16, 0xBEEF, 0x7E}, 0x178,
                    bytes);
  const auto report = decoded<UpdateReport>(0x178, bytes);
  EXPECT_EQ(report.state, UpdateState::failed);
  EXPECT_EQ(report.active_slot, 2);
  EXPECT_EQ(report.reason, UpdateReason::digest_mismatch);
  EXPECT_EQ(report.next_block, 912);
  EXPECT_EQ(report.window, 16);
  EXPECT_EQ(report.transfer_id, 0xBEEF);
  EXPECT_EQ(report.active_sequence, 0x7E);
}

// CAN FD frames: each part laid out as its classical message in its own 8
// bytes (the bytes after the part's DLC 0), the frame flagged FD.
hal::CanFrame fd_frame_of(std::uint32_t id, const Bytes& bytes) {
  hal::CanFrame frame = frame_of(id, bytes);
  frame.flags = hal::kCanFdFrame;
  return frame;
}

Bytes joined(std::initializer_list<Bytes> parts) {
  Bytes bytes;
  for (const Bytes& part : parts) {
    Bytes padded = part;
    padded.resize(8, 0x00);
    bytes.insert(bytes.end(), padded.begin(), padded.end());
  }
  return bytes;
}

template <typename Message>
void expect_fd_encodes_to(const Message& message, std::uint32_t id, const Bytes& bytes) {
  expect_encodes_to(message, id, bytes);
  hal::CanFrame frame;
  encode(message, frame);
  EXPECT_EQ(frame.flags, hal::kCanFdFrame);
}

template <typename Message>
Message fd_decoded(std::uint32_t id, const Bytes& bytes) {
  SCOPED_TRACE("decoding golden FD frame " + golden_name(id, bytes));
  Message message;
  EXPECT_STREQ(to_string(decode(fd_frame_of(id, bytes), message)), to_string(DecodeStatus::ok));
  // The same bytes as a classical frame, or a byte cut off, are refused.
  EXPECT_STREQ(to_string(decode(frame_of(id, bytes), message)), to_string(DecodeStatus::wrong_dlc));
  Bytes shorter(bytes.begin(), bytes.end() - 8);
  EXPECT_STREQ(to_string(decode(fd_frame_of(id, shorter), message)), to_string(DecodeStatus::wrong_dlc));
  return message;
}

// 0x134, 32 bytes: POSE_POSITION_XY, POSE_POSITION_Z, POSE_ORIENTATION,
// POSE_UNCERTAINTY in bytes 0, 8, 16, 24; FLAGS bit 2 says the last holds radii.
TEST(GoldenFrames, PoseFd) {
  // The golden parts above; FLAGS 0x07 (compensated, extrapolating, radii).
  const Bytes with_radii = joined({{0x13, 0x68, 0xF9, 0xFF, 0x66, 0x56, 0x01, 0x00},
                                   {0x25, 0x49, 0x00, 0x00, 0x07, 0x81},
                                   {0x66, 0x66, 0xCD, 0xCC, 0x99, 0x19, 0x33, 0x33},
                                   {0xC4, 0x09, 0x39, 0x30, 0x46, 0x02, 0xEE}});
  PoseFd sent{{-4321.09, 876.54}, {187.25, true, 0x81}, {0.8, -0.4, 0.2, 0.4}, {}};
  sent.position_z.extrapolating = true;
  sent.position_z.radii = true;
  sent.uncertainty.r95_position_mm = 2.5;
  sent.uncertainty.r95_orientation_deg = 12.345;
  sent.uncertainty.latent_share = 0.35;
  sent.uncertainty.outside_range = true;
  sent.uncertainty.sequence = 0xEE;
  expect_fd_encodes_to(sent, 0x134, with_radii);
  auto pose = fd_decoded<PoseFd>(0x134, with_radii);
  expect_physical(pose.position_xy.x_mm, -4321.09);
  expect_physical(pose.position_xy.y_mm, 876.54);
  expect_physical(pose.position_z.z_mm, 187.25);
  EXPECT_TRUE(pose.position_z.compensated);
  EXPECT_TRUE(pose.position_z.extrapolating);
  EXPECT_TRUE(pose.position_z.radii);
  EXPECT_EQ(pose.position_z.sequence, 0x81);
  expect_physical(pose.orientation.qw, 26214.0 / 32767);
  expect_physical(pose.orientation.qz, 13107.0 / 32767);
  expect_physical(pose.uncertainty.r95_position_mm, 2.5);
  expect_physical(pose.uncertainty.r95_orientation_deg, 12.345);
  EXPECT_TRUE(pose.uncertainty.outside_range);
  EXPECT_EQ(pose.uncertainty.sequence, 0xEE);

  // Without radii: FLAGS 0x01 and the uncertainty part 0, whatever it held.
  const Bytes without_radii = joined({{0x13, 0x68, 0xF9, 0xFF, 0x66, 0x56, 0x01, 0x00},
                                      {0x25, 0x49, 0x00, 0x00, 0x01, 0x81},
                                      {0x66, 0x66, 0xCD, 0xCC, 0x99, 0x19, 0x33, 0x33},
                                      {}});
  sent.position_z.extrapolating = false;
  sent.position_z.radii = false;
  expect_fd_encodes_to(sent, 0x134, without_radii);
  pose = fd_decoded<PoseFd>(0x134, without_radii);
  EXPECT_FALSE(pose.position_z.radii);
  EXPECT_EQ(pose.uncertainty.r95_position_mm, 0.0);

  // A reserved byte of a part set: refused.
  Bytes reserved = with_radii;
  reserved[8 + 6] = 0x01;  // POSE_POSITION_Z has 6 bytes
  PoseFd refused;
  EXPECT_EQ(decode(fd_frame_of(0x134, reserved), refused), DecodeStatus::reserved_bits_set);
}

// 0x123, 24 bytes: TARGET_ORIENTATION, TARGET_POSITION_XY, TARGET_POSITION_Z.
TEST(GoldenFrames, TargetFd) {
  const Bytes bytes = joined({{0xCD, 0x0C, 0x99, 0x59, 0x33, 0xF3, 0x67, 0xA6},
                              {0x4E, 0x61, 0xBC, 0x00, 0xC1, 0x4B, 0x69, 0xFF},
                              {0x26, 0x9E, 0xFF, 0xFF, 0x05, 0x5A}});
  TargetFd sent{{0.1, 0.7, -0.1, -0.7}, {123456.78, -98765.43}, {-250.5, TargetMode::pose, false, 0x5A}};
  sent.position_z.refuse_extrapolating = true;
  expect_fd_encodes_to(sent, 0x123, bytes);
  const auto target = fd_decoded<TargetFd>(0x123, bytes);
  expect_physical(target.orientation.qx, 22937.0 / 32767);
  expect_physical(target.position_xy.x_mm, 123456.78);
  expect_physical(target.position_xy.y_mm, -98765.43);
  expect_physical(target.position_z.z_mm, -250.5);
  EXPECT_EQ(target.position_z.mode, TargetMode::pose);
  EXPECT_TRUE(target.position_z.refuse_extrapolating);
  EXPECT_EQ(target.position_z.sequence, 0x5A);
}

// 0x118 + g, 32 bytes: CABLE_SETPOINT of segments 4g .. 4g + 3; a segment
// the robot lacks has every length 65535.
TEST(GoldenFrames, CableSetpointsFd) {
  // A six-segment robot's second frame, 0x119: segments 4 and 5, then two absent.
  const Bytes bytes = joined({{0x10, 0x27, 0x39, 0x30, 0x01, 0x00, 0xFE, 0xFF},
                              {0x32, 0x00, 0xE4, 0x57, 0x31, 0x75, 0x92, 0x10},
                              {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF},
                              {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}});
  CableSetpointsFd sent;
  sent.index = 1;
  sent.segment_count = 2;
  sent.segments[0] = CableSetpoint{4, {100.0, 123.45, 0.01, 655.34}};
  sent.segments[1] = CableSetpoint{5, {0.5, 225.0, 300.01, 42.42}};
  expect_fd_encodes_to(sent, 0x119, bytes);
  const auto setpoints = fd_decoded<CableSetpointsFd>(0x119, bytes);
  EXPECT_EQ(setpoints.index, 1);
  ASSERT_EQ(setpoints.segment_count, 2);
  EXPECT_EQ(setpoints.segments[0].segment, 4);
  EXPECT_EQ(setpoints.segments[1].segment, 5);
  expect_physical(setpoints.segments[0].lengths_mm[1], 123.45);
  expect_physical(setpoints.segments[1].lengths_mm[3], 42.42);
}

bool passes(const hal::CanFilter& filter, std::uint32_t id) { return (id & filter.mask) == (filter.id & filter.mask); }

// The FD frames' identifiers: in the frame groups the runtime's filters
// pass (the host's targets, the pose, the drives' setpoints), and every FD
// message has a golden frame above.
TEST(GoldenFrames, FdMessagesSitInTheirFrameGroups) {
  EXPECT_TRUE(passes(kTargetFrames, 0x123));
  EXPECT_TRUE(passes(kPoseFrames, 0x134));
  EXPECT_TRUE(passes(kCableSetpointsFdFrames, 0x118));
  EXPECT_TRUE(passes(kCableSetpointsFdFrames, 0x119));
  EXPECT_FALSE(passes(kCableSetpointsFdFrames, 0x110));  // CABLE_SETPOINT_0
  EXPECT_FALSE(passes(kCableFeedbackFrames, 0x118));
  for (const FdMessageSpec* message : kFdMessages) {
    SCOPED_TRACE(message->name);
    EXPECT_TRUE(passes(message->group, message->id));
    EXPECT_TRUE(passes(message->group, message->id + message->id_count - 1u));
  }
  constexpr std::uint32_t kGoldenFdIds[] = {0x119, 0x123, 0x134};
  for (const FdMessageSpec* message : kFdMessages) {
    const bool covered = std::any_of(std::begin(kGoldenFdIds), std::end(kGoldenFdIds),
                                     [&](std::uint32_t id) { return message->carries(id); });
    EXPECT_TRUE(covered) << message->name << " has no golden frame";
  }
}

// A message added to the table needs its golden frame above.
TEST(GoldenFrames, EveryMessageOfTheTableHasOne) {
  constexpr std::uint32_t kGoldenIds[] = {0x102, 0x117, 0x120, 0x121, 0x122, 0x130, 0x131, 0x132, 0x133,
                                          0x140, 0x150, 0x151, 0x160, 0x161, 0x162, 0x170, 0x171, 0x172, 0x173, 0x178};
  for (const MessageSpec* message : kMessages) {
    const bool covered = std::any_of(std::begin(kGoldenIds), std::end(kGoldenIds),
                                     [&](std::uint32_t id) { return message->carries(id); });
    EXPECT_TRUE(covered) << message->name << " has no golden frame";
  }
  EXPECT_EQ(std::size(kGoldenIds), std::size(kMessages));
}

// A bus that keeps what is sent and hands back what a test puts in it.
class RecordingBus final : public hal::CanBus {
 public:
  hal::CanStatus send(const hal::CanFrame& frame) override {
    sent.push_back(frame);
    return hal::CanStatus::ok;
  }
  hal::CanStatus receive(hal::CanFrame& frame) override {
    if (incoming.empty()) return hal::CanStatus::empty;
    frame = incoming.front();
    incoming.erase(incoming.begin());
    return hal::CanStatus::ok;
  }
  bool set_filters(const hal::CanFilter* filters, std::size_t count) override {
    this->filters.assign(filters, filters + count);
    return true;
  }
  hal::CanErrorCounters error_counters() const override { return {}; }
  bool fd_capable() const override { return true; }

  std::vector<hal::CanFrame> sent, incoming;
  std::vector<hal::CanFilter> filters;
};

// The identifier base moved to 0x300 (messages.hpp, id_offset): the same
// golden bytes on identifiers 0x200 higher, each way, and the filters with
// them; a frame at the default identifiers is then foreign.
TEST(GoldenFrames, AtIdentifierBase0x300EveryFrameMovesWithTheWindow) {
  RecordingBus wire;
  hal::ShiftedCanBus bus(wire, id_offset(0x300));
  const Bytes feedback{0x10, 0x27, 0x39, 0x30, 0x01, 0x00, 0xFE, 0xFF};
  hal::CanFrame frame;
  ASSERT_TRUE(encode(CableFeedback{2, {100.0, 123.45, 0.01, 655.34}}, frame));
  ASSERT_EQ(bus.send(frame), hal::CanStatus::ok);
  // UPDATE_REPORT, the window's last message: 0x178 -> 0x378.
  encode(UpdateReport{}, frame);
  ASSERT_EQ(bus.send(frame), hal::CanStatus::ok);
  ASSERT_EQ(wire.sent.size(), 2u);
  EXPECT_EQ(wire.sent[0].id, 0x302u);
  EXPECT_EQ(Bytes(wire.sent[0].data, wire.sent[0].data + wire.sent[0].dlc), feedback);
  EXPECT_EQ(wire.sent[1].id, 0x378u);

  wire.incoming.push_back(frame_of(0x302, feedback));
  wire.incoming.push_back(frame_of(0x102, feedback));  // the default identifier: not ours here
  hal::CanFrame received;
  ASSERT_EQ(bus.receive(received), hal::CanStatus::ok);
  EXPECT_EQ(received.id, 0x102u);
  CableFeedback cables;
  ASSERT_EQ(decode(received, cables), DecodeStatus::ok);
  EXPECT_EQ(cables.segment, 2);
  ASSERT_EQ(bus.receive(received), hal::CanStatus::ok);
  EXPECT_EQ(received.id, 0x702u);
  for (const MessageSpec* message : kMessages) EXPECT_FALSE(message->carries(received.id)) << message->name;

  const hal::CanFilter groups[] = {kCableFeedbackFrames, kTargetFrames, kUpdateRequestFrames};
  ASSERT_TRUE(bus.set_filters(groups, 3));
  ASSERT_EQ(wire.filters.size(), 3u);
  EXPECT_EQ(wire.filters[0].id, 0x300u);
  EXPECT_EQ(wire.filters[0].mask, 0x7F8u);
  EXPECT_EQ(wire.filters[1].id, 0x320u);
  EXPECT_EQ(wire.filters[2].id, 0x370u);

  // An FD frame moves with the window too, and keeps its flags: POSE_FD
  // 0x134 -> 0x334.
  PoseFd pose;
  encode(pose, frame);
  ASSERT_EQ(bus.send(frame), hal::CanStatus::ok);
  EXPECT_EQ(wire.sent.back().id, 0x334u);
  EXPECT_EQ(wire.sent.back().flags, hal::kCanFdFrame);
  EXPECT_EQ(wire.sent.back().dlc, 32);
}

}  // namespace
}  // namespace cdcr::firmware::protocol
