// The DBC file and protocol.hpp describe the same frames, signal by signal,
// and the codec round-trips through the scalings they declare.

#include <cmath>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include <cdcr/firmware/protocol.hpp>

namespace cdcr::firmware::protocol {
namespace {

struct DbcSignal {
  int start_bit;
  int length_bits;
  bool is_signed;
  double factor;
  double offset;
  double minimum;
  double maximum;
  std::string unit;
};
struct DbcMessage {
  std::string name;
  int dlc;
  std::string sender;
  std::map<std::string, DbcSignal> signals;
};

std::map<std::uint32_t, DbcMessage> read_dbc(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  const std::regex message(R"re(^BO_ (\d+) (\w+): (\d+) (\w+)\s*$)re");
  const std::regex signal(
      R"re(^ SG_ (\w+) : (\d+)\|(\d+)@1([+-]) \(([^,]+),([^)]+)\) \[([^|]+)\|([^\]]+)\] "([^"]*)" .+$)re");
  std::map<std::uint32_t, DbcMessage> messages;
  DbcMessage* current = nullptr;
  std::string line;
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_match(line, m, message)) {
      current = &messages[static_cast<std::uint32_t>(std::stoul(m[1]))];
      current->name = m[2];
      current->dlc = std::stoi(m[3]);
      current->sender = m[4];
    } else if (std::regex_match(line, m, signal)) {
      EXPECT_NE(current, nullptr) << line;
      if (current == nullptr) continue;
      current->signals[m[1]] = DbcSignal{std::stoi(m[2]), std::stoi(m[3]), m[4] == "-", std::stod(m[5]),
                                         std::stod(m[6]), std::stod(m[7]), std::stod(m[8]), m[9]};
    } else {
      EXPECT_EQ(line.rfind(" SG_", 0), std::string::npos) << "unparsed signal line: " << line;
      EXPECT_EQ(line.rfind("BO_ ", 0), std::string::npos) << "unparsed message line: " << line;
    }
  }
  return messages;
}

TEST(RuntimeProtocol, DbcAgreesWithTheHeader) {
  const auto dbc = read_dbc(CDCR_DBC_PATH);
  ASSERT_EQ(dbc.size(), std::size(kMessages));
  for (const MessageSpec& spec : kMessages) {
    SCOPED_TRACE(spec.name);
    const auto found = dbc.find(spec.id);
    ASSERT_NE(found, dbc.end());
    const DbcMessage& message = found->second;
    EXPECT_EQ(message.name, spec.name);
    EXPECT_EQ(message.dlc, spec.dlc);
    EXPECT_EQ(message.sender, spec.sender);
    ASSERT_EQ(message.signals.size(), spec.signal_count);
    for (int i = 0; i < spec.signal_count; ++i) {
      const SignalSpec& s = spec.signals[i];
      SCOPED_TRACE(s.name);
      const auto sig = message.signals.find(s.name);
      ASSERT_NE(sig, message.signals.end());
      EXPECT_EQ(sig->second.start_bit, s.start_bit);
      EXPECT_EQ(sig->second.length_bits, s.length_bits);
      EXPECT_EQ(sig->second.is_signed, s.is_signed);
      EXPECT_NEAR(sig->second.factor, s.factor, 1e-15);
      EXPECT_EQ(sig->second.offset, s.offset);
      EXPECT_NEAR(sig->second.minimum, s.minimum, 1e-9);
      EXPECT_NEAR(sig->second.maximum, s.maximum, 1e-9);
      EXPECT_EQ(sig->second.unit, s.unit);
      EXPECT_LE(s.start_bit + s.length_bits, 8 * spec.dlc);
    }
  }
}

TEST(RuntimeProtocol, IdentifiersAreUniqueStandardIds) {
  std::map<std::uint32_t, int> seen;
  for (const MessageSpec& spec : kMessages) {
    EXPECT_LE(spec.id, 0x7FFu) << spec.name;
    EXPECT_EQ(seen[spec.id]++, 0) << spec.name;
  }
}

TEST(RuntimeProtocol, CableFramesRoundTripWithinHalfAQuantum) {
  const double lengths_mm[4] = {0.01, 119.996, 225.3349, 655.34};
  hal::CanFrame frame;
  ASSERT_TRUE(encode_cables(kCableFeedbackBaseId + 3, lengths_mm, frame));
  EXPECT_EQ(frame.id, kCableFeedbackBaseId + 3);
  EXPECT_EQ(frame.dlc, 8);
  double decoded_mm[4];
  ASSERT_EQ(decode_cables(frame, decoded_mm), CableFrameStatus::ok);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(decoded_mm[k], lengths_mm[k], 0.005 + 1e-12);
  EXPECT_EQ(frame.data[0], 1);  // little-endian: 0.01 mm is raw 1
  EXPECT_EQ(frame.data[1], 0);
}

TEST(RuntimeProtocol, CableEncoderRefusesWhatItCannotRepresent) {
  hal::CanFrame frame;
  const double nan_mm[4] = {100, std::nan(""), 100, 100};
  const double negative_mm[4] = {100, -1, 100, 100};
  const double too_long_mm[4] = {100, 700, 100, 100};
  EXPECT_FALSE(encode_cables(kCableSetpointBaseId, nan_mm, frame));
  EXPECT_FALSE(encode_cables(kCableSetpointBaseId, negative_mm, frame));
  EXPECT_FALSE(encode_cables(kCableSetpointBaseId, too_long_mm, frame));
}

TEST(RuntimeProtocol, CableDecoderRejectsMalformedFrames) {
  double lengths_mm[4];
  hal::CanFrame frame = make_frame(kCableFeedbackBaseId, 6);
  EXPECT_EQ(decode_cables(frame, lengths_mm), CableFrameStatus::wrong_dlc);
  frame = make_frame(kCableFeedbackBaseId, 8);
  for (int k = 0; k < 4; ++k) put_raw(frame, signal::cable[k], 10000);
  put_raw(frame, signal::cable[2], kCableNotAvailable);
  EXPECT_EQ(decode_cables(frame, lengths_mm), CableFrameStatus::not_available);
  put_raw(frame, signal::cable[2], 0);
  EXPECT_EQ(decode_cables(frame, lengths_mm), CableFrameStatus::not_positive);
}

TEST(RuntimeProtocol, SignedSignalsSignExtendAndSaturate) {
  hal::CanFrame frame = make_frame(kPosePositionXyId, 8);
  put(frame, signal::position_xy[0], -1234.567);
  put(frame, signal::position_xy[1], 1e12);
  EXPECT_NEAR(get(frame, signal::position_xy[0]), -1234.57, 1e-9);
  EXPECT_EQ(get_raw(frame, signal::position_xy[1]), 2147483647);
  frame = make_frame(kPoseOrientationId, 8);
  put(frame, signal::quaternion[0], 1.0);
  put(frame, signal::quaternion[1], -1.0);
  EXPECT_EQ(get_raw(frame, signal::quaternion[0]), 32767);
  EXPECT_EQ(get_raw(frame, signal::quaternion[1]), -32767);
}

}  // namespace
}  // namespace cdcr::firmware::protocol
