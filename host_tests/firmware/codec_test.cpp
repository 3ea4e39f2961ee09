// The protocol codec: the generic bit-field routines, the table's own
// consistency (signals inside their frame and apart, one filter per frame
// group, value tables matching the enums), and every typed frame's encode and
// decode, with byte patterns written out by hand where the layout matters.

#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include <cdcr/firmware/fault_detail.hpp>
#include <cdcr/firmware/protocol.hpp>

namespace cdcr::firmware::protocol {
namespace {

hal::CanFrame frame_of(std::uint32_t id, std::vector<std::uint8_t> bytes) {
  hal::CanFrame frame;
  frame.id = id;
  frame.dlc = static_cast<std::uint8_t>(bytes.size());
  for (std::size_t i = 0; i < bytes.size(); ++i) frame.data[i] = bytes[i];
  return frame;
}

std::vector<std::uint8_t> bytes_of(const hal::CanFrame& frame) {
  return std::vector<std::uint8_t>(frame.data, frame.data + frame.dlc);
}

// --- the bit-field codec -------------------------------------------------

TEST(SignalCodec, ReadsAndWritesFieldsAcrossByteBoundaries) {
  constexpr SignalSpec kThirteenBits{"A", 5, 13, true, 1, 0, -4096, 4095, ""};
  constexpr SignalSpec kThirtyTwoBits{"B", 20, 32, false, 1, 0, 0, 4294967295.0, ""};
  hal::CanFrame frame;
  for (auto& byte : frame.data) byte = 0xFF;
  write_raw(frame, kThirteenBits, -1000);
  EXPECT_EQ(read_raw(frame, kThirteenBits), -1000);
  // Bits 0..4 and 18.. are untouched.
  EXPECT_EQ(frame.data[0] & 0x1F, 0x1F);
  EXPECT_EQ(frame.data[2] & 0xFC, 0xFC);
  // -1000 in 13 bits is 0x1C18: bits 5..17.
  EXPECT_EQ(frame.data[0] >> 5, 0x18 & 0x07);
  EXPECT_EQ(frame.data[1], (0x1C18 >> 3) & 0xFF);
  EXPECT_EQ(frame.data[2] & 0x03, (0x1C18 >> 11) & 0x03);

  for (auto& byte : frame.data) byte = 0;
  write_raw(frame, kThirtyTwoBits, 0xDEADBEEF);
  EXPECT_EQ(read_raw(frame, kThirtyTwoBits), 0xDEADBEEF);
  EXPECT_EQ(frame.data[2], 0xF0);  // 0xDEADBEEF << 20, little-endian
  EXPECT_EQ(frame.data[3], 0xEE);
  EXPECT_EQ(frame.data[4], 0xDB);
  EXPECT_EQ(frame.data[5], 0xEA);
  EXPECT_EQ(frame.data[6], 0x0D);
  EXPECT_EQ(frame.data[7], 0x00);
}

TEST(SignalCodec, SignedFieldsSignExtend) {
  constexpr SignalSpec kFourBits{"S", 12, 4, true, 1, 0, -8, 7, ""};
  hal::CanFrame frame;
  write_raw(frame, kFourBits, -8);
  EXPECT_EQ(frame.data[1], 0x80);
  EXPECT_EQ(read_raw(frame, kFourBits), -8);
  write_raw(frame, kFourBits, 7);
  EXPECT_EQ(read_raw(frame, kFourBits), 7);
}

TEST(SignalCodec, RangesFollowTheDeclaredPhysicalRange) {
  EXPECT_EQ(raw_minimum(cable_lengths::kL1), 0);
  EXPECT_EQ(raw_maximum(cable_lengths::kL1), 65535);
  EXPECT_EQ(raw_minimum(quaternion::kQw), -32767);  // -32768 would be below -1
  EXPECT_EQ(raw_maximum(quaternion::kQw), 32767);
  EXPECT_EQ(raw_minimum(position_xy::kX), -2147483648LL);
  EXPECT_EQ(raw_maximum(position_xy::kX), 2147483647LL);
  EXPECT_EQ(raw_maximum(ik_report::kOutcome), 7);
  EXPECT_EQ(raw_maximum(ik_report::kPositionResidual), 65535);
}

TEST(SignalCodec, SaturatingEncodingClampsAndSendsNanAsTheMaximum) {
  const SignalSpec& residual = ik_report::kPositionResidual;
  EXPECT_EQ(to_raw_saturating(residual, 1.2345), 1235);  // 1.2345 mm / 0.001, rounded to nearest
  EXPECT_EQ(to_raw_saturating(residual, 1e9), 65535);
  EXPECT_EQ(to_raw_saturating(residual, std::numeric_limits<double>::infinity()), 65535);
  EXPECT_EQ(to_raw_saturating(residual, std::nan("")), 65535);
  EXPECT_EQ(to_raw_saturating(residual, -3.0), 0);
  EXPECT_EQ(to_raw_saturating(position_xy::kX, -1e12), -2147483648LL);
  EXPECT_EQ(to_raw_saturating(quaternion::kQx, -1.5), -32767);
}

TEST(SignalCodec, CheckedEncodingRefusesWhatItCannotRepresent) {
  std::int64_t raw = 0;
  EXPECT_TRUE(to_raw_checked(cable_lengths::kL1, 655.35, raw));
  EXPECT_EQ(raw, 65535);
  EXPECT_FALSE(to_raw_checked(cable_lengths::kL1, 655.36, raw));
  EXPECT_FALSE(to_raw_checked(cable_lengths::kL1, -0.01, raw));
  EXPECT_FALSE(to_raw_checked(cable_lengths::kL1, std::nan(""), raw));
  EXPECT_TRUE(to_raw_checked(cable_lengths::kL1, -0.004, raw));  // rounds to 0, inside the range
  EXPECT_EQ(raw, 0);
}

// --- the table ------------------------------------------------------------

// The single-precision shortcut must give the double computation's raw
// value for every float: random lengths over the whole range, and the floats
// nearest each half-way point, where a rounding in single precision would
// go the other way.
TEST(SignalCodec, SinglePrecisionScalingMatchesTheDoubleOne) {
  const SignalSpec& spec = cable_lengths::kL1;
  std::uint32_t state = 12345;
  const auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return float(state >> 8) / 16777216.0f;
  };
  int compared = 0;
  const auto same = [&](float length_mm) {
    std::int64_t expected = -1, actual = -2;
    const bool expected_ok = to_raw_checked(spec, double(length_mm), expected);
    const bool actual_ok = to_raw_checked_single(spec, double(length_mm), actual);
    ++compared;
    if (expected_ok != actual_ok || (expected_ok && expected != actual)) {
      ADD_FAILURE() << "length " << length_mm << ": double " << expected_ok << "/" << expected << ", single "
                    << actual_ok << "/" << actual;
      return false;
    }
    return true;
  };
  for (int i = 0; i < 200000; ++i) {
    if (!same(-10.0f + 700.0f * next())) return;
  }
  for (int k = 0; k < 65600; ++k) {
    const float halfway = (float(k) + 0.5f) * 0.01f;
    float below = halfway, above = halfway;
    for (int step = 0; step < 8; ++step) {
      below = std::nextafter(below, 0.0f);
      above = std::nextafter(above, 1e9f);
      if (!same(below) || !same(above) || !same(halfway)) return;
    }
  }
  for (const float special : {0.0f, -0.0f, std::numeric_limits<float>::quiet_NaN(),
                              std::numeric_limits<float>::infinity(), 1e9f, -1e9f}) {
    if (!same(special)) return;
  }
  // Doubles that are no float, next to a half-way point: the double's own
  // rounding counts.
  std::int64_t raw = 0;
  ASSERT_TRUE(to_raw_checked_single(spec, 123.454999999, raw));
  EXPECT_EQ(raw, 12345);
  ASSERT_TRUE(to_raw_checked_single(spec, 123.455000001, raw));
  EXPECT_EQ(raw, 12346);
  EXPECT_GT(compared, 300000);
}

TEST(ProtocolTable, SignalsLieInsideTheirFrameAndApart) {
  for (const MessageSpec* message : kMessages) {
    SCOPED_TRACE(message->name);
    EXPECT_GE(message->id_count, 1);
    EXPECT_LE(message->id + message->id_count - 1, 0x7FFu);  // standard identifiers
    EXPECT_LE(message->dlc, 8);
    std::uint64_t used = 0;
    for (const SignalSpec* signal : message->signals) {
      SCOPED_TRACE(signal->name);
      EXPECT_GE(signal->length_bits, 1);
      EXPECT_LE(signal->length_bits, 32);
      EXPECT_LE(signal->start_bit + signal->length_bits, 8 * message->dlc);
      EXPECT_EQ(used & signal_mask(*signal), 0u) << "overlaps another signal";
      used |= signal_mask(*signal);
      EXPECT_GT(signal->factor, 0.0);
      EXPECT_LE(raw_minimum(*signal), raw_maximum(*signal));
      for (int i = 0; i < signal->values.count; ++i) {
        EXPECT_TRUE(raw_in_range(*signal, signal->values.entries[i].value)) << signal->values.entries[i].name;
      }
    }
  }
}

TEST(ProtocolTable, IdentifiersAreUnique) {
  std::vector<int> owners(0x800, 0);
  for (const MessageSpec* message : kMessages) {
    for (int i = 0; i < message->id_count; ++i) EXPECT_EQ(owners[message->id + i]++, 0) << message->name;
  }
}

// Each frame group's filter passes its messages and no other message of the
// protocol, so a node that sets it hears exactly its group.
TEST(ProtocolTable, EachGroupFilterPassesExactlyItsMessages) {
  for (const MessageSpec* message : kMessages) {
    for (const MessageSpec* other : kMessages) {
      const bool same_group = other->group.id == message->group.id && other->group.mask == message->group.mask;
      for (int i = 0; i < other->id_count; ++i) {
        EXPECT_EQ(passes(message->group, other->id + i), same_group)
            << message->name << "'s filter and " << other->name << " " << i;
      }
    }
  }
}

TEST(ProtocolTable, ValueTablesNameEveryEnumerator) {
  for (const ValueName& v : values::kRuntimeState) {
    EXPECT_STREQ(v.name, to_string(static_cast<RuntimeState>(v.value)));
  }
  EXPECT_STREQ(to_string(static_cast<RuntimeState>(std::size(values::kRuntimeState))), "UNKNOWN");
  // Every fault code is in the table and nothing else: to_string knows
  // exactly the enumerators.
  for (int code = 0; code < 256; ++code) {
    const bool enumerator = std::string(to_string(static_cast<FaultCode>(code))) != "unknown fault";
    EXPECT_EQ(code < int(std::size(values::kFaultCode)), enumerator) << code;
  }
  for (std::size_t i = 0; i < std::size(values::kFaultCode); ++i) EXPECT_EQ(values::kFaultCode[i].value, i);
  EXPECT_EQ(static_cast<int>(IkOutcome::refused_extrapolating) + 1, int(std::size(values::kIkOutcome)));
  EXPECT_STREQ(values::kIkOutcome[static_cast<int>(IkOutcome::superseded)].name, "superseded");
  EXPECT_STREQ(values::kTargetMode[static_cast<int>(TargetMode::pose)].name, "pose");
}

// --- typed frames -----------------------------------------------------------

TEST(Frames, CableFramesRoundTripWithinHalfAQuantum) {
  const CableFeedback sent{3, {0.01, 119.996, 225.3349, 655.34}};
  hal::CanFrame frame;
  ASSERT_TRUE(encode(sent, frame));
  EXPECT_EQ(frame.id, 0x103u);
  EXPECT_EQ(frame.dlc, 8);
  EXPECT_EQ(frame.data[0], 1);  // little-endian: 0.01 mm is raw 1
  EXPECT_EQ(frame.data[1], 0);
  EXPECT_EQ(frame.data[6], 0xFE);  // 655.34 mm is raw 0xFFFE
  EXPECT_EQ(frame.data[7], 0xFF);
  CableFeedback received;
  ASSERT_EQ(decode(frame, received), DecodeStatus::ok);
  EXPECT_EQ(received.segment, 3);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(received.lengths_mm[k], sent.lengths_mm[k], 0.005 + 1e-12);
  EXPECT_DOUBLE_EQ(cable_length_as_transmitted(119.996), received.lengths_mm[1]);

  CableSetpoint setpoint;
  EXPECT_EQ(decode(frame, setpoint), DecodeStatus::wrong_id);  // feedback is not a setpoint
  ASSERT_TRUE(encode(CableSetpoint{7, {100, 100, 100, 100}}, frame));
  EXPECT_EQ(frame.id, 0x117u);
  ASSERT_EQ(decode(frame, setpoint), DecodeStatus::ok);
  EXPECT_EQ(setpoint.segment, 7);
}

TEST(Frames, CableEncoderRefusesWhatItCannotRepresent) {
  hal::CanFrame frame;
  EXPECT_FALSE(encode(CableSetpoint{0, {100, std::nan(""), 100, 100}}, frame));
  EXPECT_FALSE(encode(CableSetpoint{0, {100, -1, 100, 100}}, frame));
  EXPECT_FALSE(encode(CableSetpoint{0, {100, 0.004, 100, 100}}, frame));   // raw 0: no length
  EXPECT_FALSE(encode(CableSetpoint{0, {100, 655.35, 100, 100}}, frame));  // raw 0xFFFF: "not available"
  EXPECT_FALSE(encode(CableSetpoint{0, {100, 700, 100, 100}}, frame));
  EXPECT_FALSE(encode(CableSetpoint{8, {100, 100, 100, 100}}, frame));  // no identifier for segment 8
  EXPECT_FALSE(encode(CableSetpoint{-1, {100, 100, 100, 100}}, frame));
  EXPECT_TRUE(cable_length_encodable(655.34));
  EXPECT_FALSE(cable_length_encodable(655.349));  // rounds to the "not available" mark
}

TEST(Frames, CableDecoderRejectsMalformedFrames) {
  CableFeedback feedback;
  EXPECT_EQ(decode(frame_of(0x100, {1, 0, 1, 0, 1, 0}), feedback), DecodeStatus::wrong_dlc);
  EXPECT_EQ(decode(frame_of(0x100, {1, 0, 0xFF, 0xFF, 1, 0, 1, 0}), feedback), DecodeStatus::not_available);
  EXPECT_EQ(decode(frame_of(0x100, {0xFF, 0xFF, 1, 0, 1, 0, 1, 0}), feedback), DecodeStatus::not_available);
  EXPECT_EQ(decode(frame_of(0x100, {1, 0, 0, 0, 1, 0, 1, 0}), feedback), DecodeStatus::out_of_range);
  EXPECT_EQ(decode(frame_of(0x100, {1, 0, 1, 0, 1, 0, 0, 0}), feedback), DecodeStatus::out_of_range);
  EXPECT_EQ(decode(frame_of(0x108, {1, 0, 1, 0, 1, 0, 1, 0}), feedback), DecodeStatus::wrong_id);
  feedback.segment = 5;
  EXPECT_EQ(decode(frame_of(0x0FF, {1, 0, 1, 0, 1, 0, 1, 0}), feedback), DecodeStatus::wrong_id);
  EXPECT_EQ(feedback.segment, 5);  // untouched on failure
}

// A segment of three cables: L4 is "not available" on the wire and NaN in
// the struct, both ways; only L4 may be missing.
TEST(Frames, ASegmentOfThreeCablesLeavesL4NotAvailable) {
  hal::CanFrame frame;
  const double nan = std::nan("");
  ASSERT_TRUE(encode(CableSetpoint{2, {100, 101.5, 99.25, nan}}, frame));
  EXPECT_EQ(bytes_of(frame), (std::vector<std::uint8_t>{0x10, 0x27, 0xA6, 0x27, 0xC5, 0x26, 0xFF, 0xFF}));
  CableSetpoint setpoint;
  ASSERT_EQ(decode(frame, setpoint), DecodeStatus::ok);
  EXPECT_DOUBLE_EQ(setpoint.lengths_mm[2], 99.25);
  EXPECT_TRUE(std::isnan(setpoint.lengths_mm[3]));
  EXPECT_FALSE(encode(CableSetpoint{2, {nan, 101.5, 99.25, 100}}, frame));
  EXPECT_FALSE(encode(CableSetpoint{2, {100, 101.5, nan, 100}}, frame));
  CableFeedback feedback;
  EXPECT_EQ(decode(frame_of(0x100, {1, 0, 1, 0, 0xFF, 0xFF, 1, 0}), feedback), DecodeStatus::not_available);
  ASSERT_EQ(decode(frame_of(0x100, {1, 0, 1, 0, 1, 0, 0xFF, 0xFF}), feedback), DecodeStatus::ok);
  EXPECT_TRUE(std::isnan(feedback.lengths_mm[3]));
  // The frame a robot's cable vector gives for a segment of three.
  const Eigen::VectorXd cables = (Eigen::VectorXd(7) << 1, 2, 3, 4, 5, 6, 7).finished();
  const CableFeedback third = segment_cables_frame<CableFeedback>(1, cables, 4, 3);
  EXPECT_EQ(third.segment, 1);
  EXPECT_EQ(third.lengths_mm[0], 5);
  EXPECT_EQ(third.lengths_mm[2], 7);
  EXPECT_TRUE(std::isnan(third.lengths_mm[3]));
}

TEST(Frames, TargetPositionZCarriesModeTrackingAndSequence) {
  hal::CanFrame frame;
  encode(TargetPositionZ{-12.34, TargetMode::pose, true, 0xA5}, frame);
  // Z = -1234 = 0xFFFFFB2E; MODE bit 32, TRACKING bit 33; SEQUENCE byte 5.
  EXPECT_EQ(bytes_of(frame), (std::vector<std::uint8_t>{0x2E, 0xFB, 0xFF, 0xFF, 0x03, 0xA5}));
  EXPECT_EQ(frame.id, 0x122u);
  TargetPositionZ target;
  ASSERT_EQ(decode(frame, target), DecodeStatus::ok);
  EXPECT_DOUBLE_EQ(target.z_mm, -12.34);
  EXPECT_EQ(target.mode, TargetMode::pose);
  EXPECT_TRUE(target.tracking);
  EXPECT_EQ(target.sequence, 0xA5);
  EXPECT_FALSE(target.refuse_extrapolating);
}

TEST(Frames, TargetPositionZCarriesTheRefusalOfExtrapolatingSolutions) {
  hal::CanFrame frame;
  TargetPositionZ sent{100.0, TargetMode::position, false, 3};
  sent.refuse_extrapolating = true;
  encode(sent, frame);
  // REFUSE_EXTRAPOLATING is bit 34: byte 4, bit 2.
  EXPECT_EQ(bytes_of(frame), (std::vector<std::uint8_t>{0x10, 0x27, 0, 0, 0x04, 3}));
  TargetPositionZ target;
  ASSERT_EQ(decode(frame, target), DecodeStatus::ok);
  EXPECT_TRUE(target.refuse_extrapolating);
  EXPECT_FALSE(target.tracking);
  EXPECT_EQ(target.mode, TargetMode::position);
}

TEST(Frames, TargetPositionZOfTheFirstProtocolDecodesTheSame) {
  // Protocol 1 sent MODE as a byte, 0 or 1.
  TargetPositionZ target;
  ASSERT_EQ(decode(frame_of(0x122, {0x10, 0x27, 0, 0, 0x01, 9}), target), DecodeStatus::ok);
  EXPECT_DOUBLE_EQ(target.z_mm, 100.0);
  EXPECT_EQ(target.mode, TargetMode::pose);
  EXPECT_FALSE(target.tracking);
  EXPECT_EQ(target.sequence, 9);
  ASSERT_EQ(decode(frame_of(0x122, {0x10, 0x27, 0, 0, 0x00, 10}), target), DecodeStatus::ok);
  EXPECT_EQ(target.mode, TargetMode::position);
}

TEST(Frames, ReservedBitsMakeAFrameMalformed) {
  TargetPositionZ target;
  for (int bit = 35; bit <= 39; ++bit) {
    hal::CanFrame frame = frame_of(0x122, {0x10, 0x27, 0, 0, 0x00, 1});
    frame.data[bit / 8] |= std::uint8_t(1u << (bit % 8));
    EXPECT_EQ(decode(frame, target), DecodeStatus::reserved_bits_set) << "bit " << bit;
    EXPECT_EQ(commit_sequence(frame), 1);
  }
  IkReport report;
  EXPECT_EQ(decode(frame_of(0x140, {1, 0x10, 0, 0, 0, 0, 0, 0}), report), DecodeStatus::reserved_bits_set);
  PosePositionZ pose;
  // Bit 2 names the radii of POSE_FD's uncertainty part; bits 3 to 7 are reserved.
  EXPECT_EQ(decode(frame_of(0x131, {0, 0, 0, 0, 0x08, 0}), pose), DecodeStatus::reserved_bits_set);
  ASSERT_EQ(decode(frame_of(0x131, {0, 0, 0, 0, 0x01, 0}), pose), DecodeStatus::ok);
  EXPECT_TRUE(pose.compensated);
  EXPECT_FALSE(pose.extrapolating);
  ASSERT_EQ(decode(frame_of(0x131, {0, 0, 0, 0, 0x02, 0}), pose), DecodeStatus::ok);
  EXPECT_TRUE(pose.extrapolating);
  EXPECT_FALSE(pose.compensated);
  PoseUncertainty uncertainty;
  EXPECT_EQ(decode(frame_of(0x133, {0, 0, 0, 0, 0, 0x04, 0}), uncertainty), DecodeStatus::reserved_bits_set);
  Status status;
  // Bit 5 is HYSTERESIS_UNKNOWN; 6 and 7 are reserved.
  EXPECT_EQ(decode(frame_of(0x150, {0x41, 0, 0, 0, 0, 0, 0, 0}), status), DecodeStatus::reserved_bits_set);
  ASSERT_EQ(decode(frame_of(0x150, {0x21, 0, 0, 0, 0, 0, 0, 0}), status), DecodeStatus::ok);
  EXPECT_TRUE(status.hysteresis_unknown);
  ASSERT_EQ(decode(frame_of(0x150, {0x11, 0, 0, 0, 0, 0, 0, 0}), status), DecodeStatus::ok);
  EXPECT_EQ(status.state, RuntimeState::run);
  EXPECT_TRUE(status.extrapolating);
  EXPECT_EQ(commit_sequence(frame_of(0x122, {0, 0})), 0);  // too short to hold one
}

TEST(Frames, PoseUncertaintyLayout) {
  hal::CanFrame frame;
  PoseUncertainty sent;
  sent.r95_position_mm = 1.2345;
  sent.r95_orientation_deg = 70.0;  // saturates at 65.535
  sent.latent_share = 0.5;
  sent.extrapolating = true;
  sent.outside_range = false;
  sent.sequence = 9;
  encode(sent, frame);
  EXPECT_EQ(frame.id, 0x133u);
  // R95_POSITION 1235 = 0x04D3, R95_ORIENTATION 0xFFFF, LATENT_SHARE 100,
  // FLAGS bit 0, SEQUENCE.
  EXPECT_EQ(bytes_of(frame), (std::vector<std::uint8_t>{0xD3, 0x04, 0xFF, 0xFF, 100, 0x01, 9}));
  PoseUncertainty received;
  ASSERT_EQ(decode(frame, received), DecodeStatus::ok);
  EXPECT_NEAR(received.r95_position_mm, 1.235, 1e-9);
  EXPECT_NEAR(received.r95_orientation_deg, 65.535, 1e-9);
  EXPECT_NEAR(received.latent_share, 0.5, 1e-9);
  EXPECT_TRUE(received.extrapolating);
  EXPECT_FALSE(received.outside_range);
  EXPECT_EQ(received.sequence, 9);
  // A share above 1 is out of range.
  EXPECT_EQ(decode(frame_of(0x133, {0, 0, 0, 0, 201, 0, 0}), received), DecodeStatus::out_of_range);
}

TEST(Frames, IkReportLayout) {
  hal::CanFrame frame;
  encode(IkReport{5, IkOutcome::unreachable, 300, 1, 1.2345, 0.001}, frame);
  EXPECT_EQ(frame.id, 0x140u);
  // SEQUENCE, OUTCOME (low nibble), ITERATIONS saturated, CYCLES,
  // POSITION_RESIDUAL 1235 = 0x04D3, ORIENTATION_RESIDUAL 100 = 0x0064.
  EXPECT_EQ(bytes_of(frame), (std::vector<std::uint8_t>{0x05, 0x01, 0xFF, 0x01, 0xD3, 0x04, 0x64, 0x00}));
  IkReport report;
  ASSERT_EQ(decode(frame, report), DecodeStatus::ok);
  EXPECT_EQ(report.sequence, 5);
  EXPECT_EQ(report.outcome, IkOutcome::unreachable);
  EXPECT_EQ(report.iterations, 255);
  EXPECT_EQ(report.cycles, 1);
  EXPECT_NEAR(report.position_residual_mm, 1.235, 1e-12);
  EXPECT_NEAR(report.orientation_residual_rad, 0.001, 1e-12);
}

TEST(Frames, IkReportSaturatesAndRejectsUnknownOutcomes) {
  hal::CanFrame frame;
  encode(IkReport{0, IkOutcome::in_progress, -4, 1000, std::numeric_limits<double>::infinity(), std::nan("")}, frame);
  IkReport report;
  ASSERT_EQ(decode(frame, report), DecodeStatus::ok);
  EXPECT_EQ(report.outcome, IkOutcome::in_progress);
  EXPECT_EQ(report.iterations, 0);
  EXPECT_EQ(report.cycles, 255);
  EXPECT_DOUBLE_EQ(report.position_residual_mm, 65.535);
  EXPECT_DOUBLE_EQ(report.orientation_residual_rad, 0.65535);
  EXPECT_EQ(decode(frame_of(0x140, {0, 0x08, 0, 0, 0, 0, 0, 0}), report), DecodeStatus::out_of_range);
  EXPECT_EQ(decode(frame_of(0x140, {0, 0, 0, 0, 0, 0}), report), DecodeStatus::wrong_dlc);  // protocol 1's length
}

TEST(Frames, PoseFramesRoundTrip) {
  hal::CanFrame frame;
  encode(PosePositionXy{-1234.567, 1e12}, frame);
  PosePositionXy xy;
  ASSERT_EQ(decode(frame, xy), DecodeStatus::ok);
  EXPECT_NEAR(xy.x_mm, -1234.57, 1e-9);
  EXPECT_NEAR(xy.y_mm, 21474836.47, 1e-6);  // saturated
  TargetPositionXy target;
  EXPECT_EQ(decode(frame, target), DecodeStatus::wrong_id);

  encode(PosePositionZ{250.0, true, 17}, frame);
  EXPECT_EQ(bytes_of(frame), (std::vector<std::uint8_t>{0xA8, 0x61, 0x00, 0x00, 0x01, 17}));
  PosePositionZ z;
  ASSERT_EQ(decode(frame, z), DecodeStatus::ok);
  EXPECT_DOUBLE_EQ(z.z_mm, 250.0);
  EXPECT_TRUE(z.compensated);
  EXPECT_EQ(z.sequence, 17);

  encode(PoseOrientation{1.0, -1.0, 0.5, 0.0}, frame);
  EXPECT_EQ(bytes_of(frame), (std::vector<std::uint8_t>{0xFF, 0x7F, 0x01, 0x80, 0x00, 0x40, 0x00, 0x00}));
  PoseOrientation q;
  ASSERT_EQ(decode(frame, q), DecodeStatus::ok);
  EXPECT_DOUBLE_EQ(q.qw, 1.0);
  EXPECT_DOUBLE_EQ(q.qx, -1.0);
  EXPECT_NEAR(q.qy, 0.5, 1.0 / 32767);
  // Q15's -32768 is below the declared -1.
  TargetOrientation orientation;
  EXPECT_EQ(decode(frame_of(0x120, {0xFF, 0x7F, 0x00, 0x80, 0, 0, 0, 0}), orientation), DecodeStatus::out_of_range);
}

TEST(Frames, StatusAndStatsRoundTripWithATypedFaultDetail) {
  hal::CanFrame frame;
  encode(Status{RuntimeState::degraded, FaultCode::image_invalid, 70000, 12, 3}, frame);
  EXPECT_EQ(bytes_of(frame), (std::vector<std::uint8_t>{0x02, 0x02, 0xFF, 0xFF, 12, 0, 3, 0}));
  Status status;
  ASSERT_EQ(decode(frame, status), DecodeStatus::ok);
  EXPECT_EQ(status.state, RuntimeState::degraded);
  EXPECT_EQ(status.fault, FaultCode::image_invalid);
  EXPECT_EQ(status.overruns, 65535);
  EXPECT_EQ(decode(frame_of(0x150, {0x04, 0, 0, 0, 0, 0, 0, 0}), status), DecodeStatus::out_of_range);  // no state 4

  Stats sent;
  sent.jitter_max_us = 40;
  sent.rejected_frames = 3;
  sent.cycle_count = 0xFFFF;
  sent.fault_detail = FaultDetail(model::ImageStatus::checksum_mismatch);
  sent.stale_events = 1000;
  encode(sent, frame);
  EXPECT_EQ(bytes_of(frame), (std::vector<std::uint8_t>{40, 0, 3, 0, 0xFF, 0xFF, 7, 0xFF}));
  Stats received;
  ASSERT_EQ(decode(frame, status.fault, received), DecodeStatus::ok);
  EXPECT_EQ(received.fault_detail, FaultDetail(model::ImageStatus::checksum_mismatch));
  EXPECT_EQ(received.stale_events, 255);
  // The same byte read with another FAULT is another enum, or nothing.
  ASSERT_EQ(decode(frame, FaultCode::target_unreachable, received), DecodeStatus::ok);
  EXPECT_EQ(received.fault_detail, FaultDetail(model::Status::ik_not_converged));
  ASSERT_EQ(decode(frame, FaultCode::cable_input_stale, received), DecodeStatus::ok);
  EXPECT_EQ(received.fault_detail, FaultDetail());
}

TEST(FaultDetail, RecordsTheEnumItCarries) {
  const FaultDetail image(model::ImageStatus::truncated);
  const FaultDetail kinematics(model::Status::non_finite_input);
  EXPECT_EQ(image.kind(), FaultDetailKind::image_status);
  EXPECT_EQ(kinematics.kind(), FaultDetailKind::model_status);
  EXPECT_EQ(image.wire_value(), kinematics.wire_value());  // both 1 on the wire
  EXPECT_NE(image, kinematics);
  EXPECT_EQ(image.image_status(), model::ImageStatus::truncated);
  EXPECT_EQ(kinematics.model_status(), model::Status::non_finite_input);
  EXPECT_TRUE(image.details(FaultCode::image_invalid));
  EXPECT_FALSE(image.details(FaultCode::target_unreachable));
  EXPECT_TRUE(kinematics.details(FaultCode::cable_lengths_invalid));
  EXPECT_TRUE(FaultDetail().details(FaultCode::can_filters_refused));
}

}  // namespace
}  // namespace cdcr::firmware::protocol
