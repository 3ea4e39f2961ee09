// Golden CANopen frames, written out by hand from CiA 301 (NMT 7.2.8.3.1,
// SYNC 7.2.5, SDO 7.2.4.3.3-7 and the abort codes of table 22, heartbeat
// 7.2.8.3.2.2, EMCY 7.2.7, the predefined connection set 7.3.5) and CiA
// 402-2 (the statusword's bit patterns, table 30; the controlword's
// commands, table 28), not from the codec: identifier, DLC and bytes. Each
// is encoded and compared byte for byte, or decoded and compared field by
// field; frames CiA 301 does not allow are refused.

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/firmware/canopen/cia402.hpp>
#include <cdcr/firmware/canopen/frames.hpp>

#include "golden_frames.hpp"

namespace cdcr::firmware::canopen {
namespace {

using test_support::Bytes;
using test_support::frame_of;
std::string text(const hal::CanFrame& frame) { return test_support::frame_text(frame); }

void expect_frame(const hal::CanFrame& actual, std::uint32_t id, const Bytes& bytes) {
  EXPECT_EQ(text(actual), text(frame_of(id, bytes)));
  EXPECT_EQ(actual.flags, 0) << "a CANopen frame is a classical frame";
}

TEST(CanopenGoldenFrames, NmtCommands) {
  expect_frame(nmt_frame(NmtCommand::start, 5), 0x000, {0x01, 0x05});
  expect_frame(nmt_frame(NmtCommand::stop, 12), 0x000, {0x02, 0x0C});
  expect_frame(nmt_frame(NmtCommand::enter_pre_operational, 5), 0x000, {0x80, 0x05});
  expect_frame(nmt_frame(NmtCommand::reset_node, 0), 0x000, {0x81, 0x00});
  expect_frame(nmt_frame(NmtCommand::reset_communication, 127), 0x000, {0x82, 0x7F});
}

TEST(CanopenGoldenFrames, SyncWithoutCounter) { expect_frame(sync_frame(), 0x080, {}); }

TEST(CanopenGoldenFrames, SdoExpeditedDownloadOfEachSize) {
  hal::CanFrame frame;
  // 0x6060:00 = 8 (CSP), one byte: ccs 1, n 3, e, s = 0x2F.
  ASSERT_TRUE(sdo_download_frame(5, {0x6060, 0}, 8, 1, frame));
  expect_frame(frame, 0x605, {0x2F, 0x60, 0x60, 0x00, 0x08, 0x00, 0x00, 0x00});
  // 0x1017:00 = 50 ms, two bytes: n 2 = 0x2B.
  ASSERT_TRUE(sdo_download_frame(5, {0x1017, 0}, 50, 2, frame));
  expect_frame(frame, 0x605, {0x2B, 0x17, 0x10, 0x00, 0x32, 0x00, 0x00, 0x00});
  // Three bytes: n 1 = 0x27.
  ASSERT_TRUE(sdo_download_frame(9, {0x2000, 3}, 0xABCDEF, 3, frame));
  expect_frame(frame, 0x609, {0x27, 0x00, 0x20, 0x03, 0xEF, 0xCD, 0xAB, 0x00});
  // 0x1600:01 = 0x60400010 (the controlword, 16 bits), four bytes: 0x23.
  ASSERT_TRUE(sdo_download_frame(5, {0x1600, 1}, 0x60400010, 4, frame));
  expect_frame(frame, 0x605, {0x23, 0x00, 0x16, 0x01, 0x10, 0x00, 0x40, 0x60});
  // 0x1400:01 with bit 31 set: the PDO made invalid.
  ASSERT_TRUE(sdo_download_frame(127, {0x1400, 1}, 0x800002FF, 4, frame));
  expect_frame(frame, 0x67F, {0x23, 0x00, 0x14, 0x01, 0xFF, 0x02, 0x00, 0x80});

  EXPECT_FALSE(sdo_download_frame(0, {0x6060, 0}, 8, 1, frame)) << "node 0 is no SDO server";
  EXPECT_FALSE(sdo_download_frame(128, {0x6060, 0}, 8, 1, frame));
  EXPECT_FALSE(sdo_download_frame(5, {0x6060, 0}, 8, 0, frame)) << "an expedited write holds 1 to 4 bytes";
  EXPECT_FALSE(sdo_download_frame(5, {0x6060, 0}, 8, 5, frame));
}

TEST(CanopenGoldenFrames, SdoUploadRequest) {
  hal::CanFrame frame;
  ASSERT_TRUE(sdo_upload_frame(5, {0x6061, 0}, frame));
  expect_frame(frame, 0x605, {0x40, 0x61, 0x60, 0x00, 0x00, 0x00, 0x00, 0x00});
}

TEST(CanopenGoldenFrames, SdoRepliesDecoded) {
  SdoReply reply;
  ASSERT_TRUE(decode_sdo_reply(frame_of(0x585, {0x60, 0x60, 0x60, 0x00, 0x00, 0x00, 0x00, 0x00}), reply));
  EXPECT_EQ(reply.kind, SdoReply::Kind::download_done);
  EXPECT_EQ(reply.node, 5);
  EXPECT_EQ(reply.object.index, 0x6060);
  EXPECT_EQ(reply.object.subindex, 0);

  // 0x6061:00 read back as 8, one byte (scs 2, n 3, e, s = 0x4F).
  ASSERT_TRUE(decode_sdo_reply(frame_of(0x585, {0x4F, 0x61, 0x60, 0x00, 0x08, 0xAA, 0xBB, 0xCC}), reply));
  EXPECT_EQ(reply.kind, SdoReply::Kind::upload_value);
  EXPECT_EQ(reply.size, 1);
  EXPECT_EQ(reply.value, 8u) << "the bytes beyond the stated size are not data";
  EXPECT_EQ(reply.object.index, 0x6061);

  // 0x6064:00 = -1000 counts, four bytes (0x43).
  ASSERT_TRUE(decode_sdo_reply(frame_of(0x58C, {0x43, 0x64, 0x60, 0x00, 0x18, 0xFC, 0xFF, 0xFF}), reply));
  EXPECT_EQ(reply.kind, SdoReply::Kind::upload_value);
  EXPECT_EQ(reply.node, 12);
  EXPECT_EQ(reply.size, 4);
  EXPECT_EQ(static_cast<std::int32_t>(reply.value), -1000);

  // Two bytes (0x4B) and an expedited reply without the size (0x42: all four).
  ASSERT_TRUE(decode_sdo_reply(frame_of(0x585, {0x4B, 0x17, 0x10, 0x00, 0x32, 0x00, 0x11, 0x22}), reply));
  EXPECT_EQ(reply.size, 2);
  EXPECT_EQ(reply.value, 50u);
  ASSERT_TRUE(decode_sdo_reply(frame_of(0x585, {0x42, 0x06, 0x10, 0x00, 0xE8, 0x03, 0x00, 0x00}), reply));
  EXPECT_EQ(reply.size, 4);
  EXPECT_EQ(reply.value, 1000u);

  // Abort: 0x06010002, "attempt to write a read only object".
  ASSERT_TRUE(decode_sdo_reply(frame_of(0x585, {0x80, 0x41, 0x60, 0x00, 0x02, 0x00, 0x01, 0x06}), reply));
  EXPECT_EQ(reply.kind, SdoReply::Kind::abort);
  EXPECT_EQ(reply.abort_code, sdo::kAbortReadOnly);
  EXPECT_EQ(reply.object.index, 0x6041);

  // A segmented upload's initiate reply (0x41: size in the data, not expedited).
  ASSERT_TRUE(decode_sdo_reply(frame_of(0x585, {0x41, 0x08, 0x10, 0x00, 0x10, 0x00, 0x00, 0x00}), reply));
  EXPECT_EQ(reply.kind, SdoReply::Kind::not_expedited);
}

TEST(CanopenGoldenFrames, SdoRepliesRefused) {
  SdoReply reply;
  const Bytes done = {0x60, 0x60, 0x60, 0x00, 0x00, 0x00, 0x00, 0x00};
  EXPECT_FALSE(decode_sdo_reply(frame_of(0x605, done), reply)) << "a request, not a reply";
  EXPECT_FALSE(decode_sdo_reply(frame_of(0x580, done), reply)) << "node 0";
  EXPECT_FALSE(decode_sdo_reply(frame_of(0x585, {0x60, 0x60, 0x60, 0x00}), reply)) << "an SDO frame is 8 bytes";
  EXPECT_FALSE(decode_sdo_reply(frame_of(0x585, {0x61, 0x60, 0x60, 0x00, 0, 0, 0, 0}), reply))
      << "download response with a reserved bit set";
  EXPECT_FALSE(decode_sdo_reply(frame_of(0x585, {0x20, 0x60, 0x60, 0x00, 0, 0, 0, 0}), reply))
      << "scs 1 is a segment's reply, never asked for";
  EXPECT_FALSE(decode_sdo_reply(frame_of(0x585, {0x53, 0x64, 0x60, 0x00, 0, 0, 0, 0}), reply))
      << "upload response with reserved bit 4 set";
  hal::CanFrame fd = frame_of(0x585, done);
  fd.flags = hal::kCanFdFrame;
  EXPECT_FALSE(decode_sdo_reply(fd, reply));
}

TEST(CanopenGoldenFrames, ProcessData) {
  // RPDO1 of node 5: controlword 0x000F (enable operation), target 100,000 counts.
  expect_frame(rpdo_frame({5, 0x000F, 100000}), 0x205, {0x0F, 0x00, 0xA0, 0x86, 0x01, 0x00});
  // Negative targets in two's complement.
  expect_frame(rpdo_frame({16, 0x0006, -2}), 0x210, {0x06, 0x00, 0xFE, 0xFF, 0xFF, 0xFF});
  // TPDO1 of node 5: statusword 0x0237 (operation enabled, remote), actual -250.
  DriveState state;
  ASSERT_TRUE(decode_tpdo(frame_of(0x185, {0x37, 0x02, 0x06, 0xFF, 0xFF, 0xFF}), state));
  EXPECT_EQ(state.node, 5);
  EXPECT_EQ(state.statusword, 0x0237);
  EXPECT_EQ(state.actual_position, -250);
  ASSERT_TRUE(decode_tpdo(frame_of(0x1FF, {0x50, 0x02, 0xFF, 0xFF, 0xFF, 0x7F}), state));
  EXPECT_EQ(state.node, 127);
  EXPECT_EQ(state.actual_position, 2147483647);
  expect_frame(tpdo_frame({5, 0x0237, -250}), 0x185, {0x37, 0x02, 0x06, 0xFF, 0xFF, 0xFF});
  DriveCommand command;
  ASSERT_TRUE(decode_rpdo(frame_of(0x205, {0x0F, 0x00, 0xA0, 0x86, 0x01, 0x00}), command));
  EXPECT_EQ(command.target_position, 100000);

  EXPECT_FALSE(decode_tpdo(frame_of(0x185, {0x37, 0x02, 0x06, 0xFF, 0xFF}), state)) << "five bytes";
  EXPECT_FALSE(decode_tpdo(frame_of(0x185, {0x37, 0x02, 0x06, 0xFF, 0xFF, 0xFF, 0x00}), state)) << "seven";
  EXPECT_FALSE(decode_tpdo(frame_of(0x205, {0x37, 0x02, 0x06, 0xFF, 0xFF, 0xFF}), state)) << "an RPDO";
  EXPECT_FALSE(decode_tpdo(frame_of(0x180, {0x37, 0x02, 0x06, 0xFF, 0xFF, 0xFF}), state)) << "node 0";
}

TEST(CanopenGoldenFrames, Heartbeat) {
  expect_frame(heartbeat_frame({5, NmtState::operational}), 0x705, {0x05});
  expect_frame(heartbeat_frame({5, NmtState::boot_up}), 0x705, {0x00});
  Heartbeat heartbeat;
  ASSERT_TRUE(decode_heartbeat(frame_of(0x70C, {0x7F}), heartbeat));
  EXPECT_EQ(heartbeat.node, 12);
  EXPECT_EQ(heartbeat.state, NmtState::pre_operational);
  ASSERT_TRUE(decode_heartbeat(frame_of(0x705, {0x04}), heartbeat));
  EXPECT_EQ(heartbeat.state, NmtState::stopped);
  EXPECT_FALSE(decode_heartbeat(frame_of(0x705, {0x85}), heartbeat)) << "the toggle bit is node guarding's";
  EXPECT_FALSE(decode_heartbeat(frame_of(0x705, {0x06}), heartbeat)) << "no such NMT state";
  EXPECT_FALSE(decode_heartbeat(frame_of(0x705, {0x05, 0x00}), heartbeat)) << "one byte";
  EXPECT_FALSE(decode_heartbeat(frame_of(0x700, {0x05}), heartbeat)) << "node 0";
}

TEST(CanopenGoldenFrames, Emergency) {
  // Node 5: 0x2310 "continuous over-current", error register 0x03 (generic, current).
  Emergency emergency;
  ASSERT_TRUE(decode_emergency(frame_of(0x085, {0x10, 0x23, 0x03, 0x00, 0x00, 0x00, 0x00, 0x00}), emergency));
  EXPECT_EQ(emergency.node, 5);
  EXPECT_EQ(emergency.error_code, 0x2310);
  EXPECT_EQ(emergency.error_register, 0x03);
  EXPECT_FALSE(emergency.clears());
  // Error reset from node 12, with manufacturer bytes.
  ASSERT_TRUE(decode_emergency(frame_of(0x08C, {0x00, 0x00, 0x00, 0x01, 0x02, 0x03, 0x04, 0x05}), emergency));
  EXPECT_TRUE(emergency.clears());
  EXPECT_EQ(emergency.manufacturer[4], 0x05);
  Emergency written;
  written.node = 5;
  written.error_code = 0x8130;  // heartbeat error
  written.error_register = 0x11;
  expect_frame(emergency_frame(written), 0x085, {0x30, 0x81, 0x11, 0x00, 0x00, 0x00, 0x00, 0x00});

  EXPECT_FALSE(decode_emergency(sync_frame(), emergency)) << "the SYNC shares the function code";
  EXPECT_FALSE(decode_emergency(frame_of(0x085, {0x10, 0x23, 0x03, 0x00, 0x00, 0x00, 0x00}), emergency));
}

TEST(Cia402, PowerStateFromStatusword) {
  using cia402::PowerState;
  using cia402::power_state;
  // Table 30's patterns, with bits the state ignores (4 voltage enabled,
  // 7 warning, 9 remote, 10 target reached) set on purpose.
  EXPECT_EQ(power_state(0x0000), PowerState::not_ready_to_switch_on);
  EXPECT_EQ(power_state(0x0230), PowerState::not_ready_to_switch_on);
  EXPECT_EQ(power_state(0x0250), PowerState::switch_on_disabled);
  EXPECT_EQ(power_state(0x0270), PowerState::switch_on_disabled);
  EXPECT_EQ(power_state(0x0231), PowerState::ready_to_switch_on);
  EXPECT_EQ(power_state(0x0233), PowerState::switched_on);
  EXPECT_EQ(power_state(0x0237), PowerState::operation_enabled);
  EXPECT_EQ(power_state(0x06B7), PowerState::operation_enabled);
  EXPECT_EQ(power_state(0x0217), PowerState::quick_stop_active);
  EXPECT_EQ(power_state(0x021F), PowerState::fault_reaction_active);
  EXPECT_EQ(power_state(0x0218), PowerState::fault);
  EXPECT_EQ(power_state(0x0238), PowerState::fault);
  EXPECT_EQ(power_state(0x0001), PowerState::unknown);
  EXPECT_EQ(power_state(0x0071), PowerState::unknown) << "ready to switch on with switch on disabled set";
}

TEST(Cia402, EnablingWalksTheTransitions) {
  using cia402::PowerState;
  using cia402::enabling_controlword;
  EXPECT_EQ(enabling_controlword(PowerState::switch_on_disabled), 0x0006);  // 2: shutdown
  EXPECT_EQ(enabling_controlword(PowerState::ready_to_switch_on), 0x0007);  // 3: switch on
  EXPECT_EQ(enabling_controlword(PowerState::switched_on), 0x000F);         // 4: enable operation
  EXPECT_EQ(enabling_controlword(PowerState::operation_enabled), 0x000F);
  EXPECT_EQ(enabling_controlword(PowerState::fault), 0x0000) << "a fault is reset only when asked";
  EXPECT_EQ(enabling_controlword(PowerState::quick_stop_active), 0x0000);
}

TEST(Cia402, ConfigurationWritesOfOneDrive) {
  cia402::ConfigurationWrite writes[cia402::kConfigurationWrites];
  cia402::configuration_writes(5, {1000, 400, 20}, writes);
  std::vector<std::string> frames;
  for (const auto& write : writes) {
    hal::CanFrame frame;
    ASSERT_TRUE(sdo_download_frame(5, write.object, write.value, write.size, frame));
    frames.push_back(text(frame));
  }
  // The RPDO made invalid, unmapped, mapped to 0x6040 (16 bits) and 0x607A
  // (32), released by every SYNC, valid on 0x205; the TPDO the same way with
  // 0x6041 and 0x6064 on 0x185; CSP; 1 ms cycle; 400 us window; 20 ms
  // heartbeat.
  const std::vector<std::string> expected = {
      "0x605 [23 00 14 01 05 02 00 80]", "0x605 [2F 00 16 00 00 00 00 00]",
      "0x605 [23 00 16 01 10 00 40 60]", "0x605 [23 00 16 02 20 00 7A 60]",
      "0x605 [2F 00 16 00 02 00 00 00]", "0x605 [2F 00 14 02 01 00 00 00]",
      "0x605 [23 00 14 01 05 02 00 00]", "0x605 [23 00 18 01 85 01 00 80]",
      "0x605 [2F 00 1A 00 00 00 00 00]", "0x605 [23 00 1A 01 10 00 41 60]",
      "0x605 [23 00 1A 02 20 00 64 60]", "0x605 [2F 00 1A 00 02 00 00 00]",
      "0x605 [2F 00 18 02 01 00 00 00]", "0x605 [23 00 18 01 85 01 00 00]",
      "0x605 [2F 60 60 00 08 00 00 00]", "0x605 [23 06 10 00 E8 03 00 00]",
      "0x605 [23 07 10 00 90 01 00 00]", "0x605 [2B 17 10 00 14 00 00 00]",
  };
  EXPECT_EQ(frames, expected);
}

}  // namespace
}  // namespace cdcr::firmware::canopen
