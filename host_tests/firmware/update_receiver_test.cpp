// The update receiver on its own: the digest's eight parts, then blocks of
// kUpdateBlockBytes as a header and its data frames, each refused as what
// a lost, repeated or reordered frame looks like; the go-back-N window of
// kUpdateWindowBlocks received but not yet durable, and the acknowledgement
// every kUpdateAckEveryBlocks durable blocks. Block CRCs are computed here
// bit by bit over the block number (little-endian) and the data.

#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/firmware/update/update_receiver.hpp>

#include "../support/reference_crc32.hpp"

namespace cdcr::firmware {
namespace {

using protocol::UpdateReason;
constexpr std::uint32_t kBlockBytes = protocol::kUpdateBlockBytes;

// Image byte i is (3 i + 1) mod 256.
std::uint8_t image_byte(std::uint32_t i) { return static_cast<std::uint8_t>((3 * i + 1) % 256); }

std::uint32_t block_crc(std::uint16_t block, std::uint32_t length) {
  std::vector<std::uint8_t> bytes = {static_cast<std::uint8_t>(block & 0xFF), static_cast<std::uint8_t>(block >> 8)};
  for (std::uint32_t i = 0; i < length; ++i) bytes.push_back(image_byte(block * kBlockBytes + i));
  return test_support::reference_crc32(bytes.data(), bytes.size());
}

hal::CanFrame header(std::uint16_t block, std::uint32_t length, std::uint32_t crc) {
  hal::CanFrame frame;
  protocol::encode(protocol::UpdateBlock{block, static_cast<std::uint8_t>(length), crc}, frame);
  return frame;
}

hal::CanFrame data(std::uint16_t block, int index) {
  protocol::UpdateData d;
  for (int k = 0; k < 8; ++k) d.bytes[k] = image_byte(block * kBlockBytes + 8 * index + k);
  hal::CanFrame frame;
  protocol::encode(d, frame);
  return frame;
}

bool reasons_are(const UpdateReceiver::Answer& answer, std::initializer_list<UpdateReason> expected) {
  if (answer.count != expected.size()) return false;
  int i = 0;
  for (UpdateReason r : expected) {
    if (answer.reasons[i++] != r) return false;
  }
  return true;
}

class UpdateReceiverTest : public ::testing::Test {
 protected:
  // A transfer of `size` bytes, none in flash yet.
  void begin(std::uint32_t size) {
    image_size = size;
    receiver.begin(size, 0);
  }
  std::uint32_t length_of(std::uint16_t block) const {
    return image_size - block * kBlockBytes < kBlockBytes ? image_size - block * kBlockBytes : kBlockBytes;
  }
  // The block's header and every data frame; every answer must be empty.
  void send_block(std::uint16_t block) {
    const std::uint32_t length = length_of(block);
    ASSERT_TRUE(reasons_are(receiver.on_block(header(block, length, block_crc(block, length)), true), {}));
    for (std::uint32_t i = 0; 8 * i < length; ++i) ASSERT_TRUE(reasons_are(receiver.on_data(data(block, int(i))), {}));
  }

  UpdateReceiver receiver;
  std::uint32_t image_size = 0;
};

TEST_F(UpdateReceiverTest, TheDigestIsCompleteWithItsEightPartsInAnyOrder) {
  std::uint8_t expected[kSha256Bytes];
  for (int part : {7, 0, 3, 3, 6, 1, 2, 5, 4}) {
    protocol::UpdateDigest d;
    d.part = static_cast<std::uint8_t>(part);
    for (int k = 0; k < 4; ++k) d.bytes[k] = expected[4 * part + k] = static_cast<std::uint8_t>(0x10 * part + k);
    hal::CanFrame frame;
    protocol::encode(d, frame);
    EXPECT_FALSE(receiver.digest_complete());
    EXPECT_TRUE(reasons_are(receiver.on_digest(frame), {}));
  }
  EXPECT_TRUE(receiver.digest_complete());
  EXPECT_EQ(std::memcmp(receiver.announced_digest(), expected, kSha256Bytes), 0);
  receiver.forget_digest();
  EXPECT_FALSE(receiver.digest_complete());
  hal::CanFrame short_frame;
  short_frame.id = protocol::update_digest::kMessage.id;
  short_frame.dlc = 2;
  EXPECT_TRUE(reasons_are(receiver.on_digest(short_frame), {UpdateReason::malformed}));
}

TEST_F(UpdateReceiverTest, BlocksAreCountedAndTheLastOneIsShort) {
  begin(2 * kBlockBytes + 20);
  EXPECT_EQ(receiver.total_blocks(), 3u);
  EXPECT_EQ(receiver.block_length(0), kBlockBytes);
  EXPECT_EQ(receiver.block_length(2), 20u);
  for (std::uint16_t b = 0; b < 3; ++b) send_block(b);
  EXPECT_EQ(receiver.received(), 3u);
  ASSERT_TRUE(receiver.block_waiting());
  // The window holds the blocks' bytes as sent.
  for (std::uint32_t i = 0; i < kBlockBytes; ++i) ASSERT_EQ(receiver.waiting_block()[i], image_byte(i));
}

TEST_F(UpdateReceiverTest, RepeatedEarlyOrLateBlocksAreRefusedAsSuch) {
  begin(4 * kBlockBytes);
  send_block(0);
  EXPECT_TRUE(reasons_are(receiver.on_block(header(0, kBlockBytes, block_crc(0, kBlockBytes)), true),
                          {UpdateReason::duplicate}));
  EXPECT_TRUE(reasons_are(receiver.on_block(header(2, kBlockBytes, block_crc(2, kBlockBytes)), true),
                          {UpdateReason::out_of_order}));
  EXPECT_TRUE(reasons_are(receiver.on_block(header(1, kBlockBytes, block_crc(1, kBlockBytes)), false),
                          {UpdateReason::no_transfer}));
  EXPECT_TRUE(reasons_are(receiver.on_block(header(1, 8, block_crc(1, 8)), true), {UpdateReason::malformed}));
  EXPECT_EQ(receiver.received(), 1u);
}

TEST_F(UpdateReceiverTest, ALostDataFrameShowsAsAMissingOrCorruptedBlock) {
  begin(3 * kBlockBytes);
  const std::uint32_t crc = block_crc(0, kBlockBytes);
  ASSERT_TRUE(reasons_are(receiver.on_block(header(0, kBlockBytes, crc), true), {}));
  // The same header again before any data: nothing lost.
  EXPECT_TRUE(reasons_are(receiver.on_block(header(0, kBlockBytes, crc), true), {}));
  receiver.on_data(data(0, 0));
  // A new header while data is missing: the block is given up.
  EXPECT_TRUE(reasons_are(receiver.on_block(header(0, kBlockBytes, crc), true), {UpdateReason::missing_block}));
  // The header was accepted after all: its data frames, one of them twice.
  for (int i = 0; i < 8; ++i) receiver.on_data(data(0, i == 7 ? 6 : i));
  EXPECT_EQ(receiver.received(), 0u);
  ASSERT_TRUE(reasons_are(receiver.on_block(header(0, kBlockBytes, crc), true), {}));
  for (int i = 0; i < 7; ++i) EXPECT_TRUE(reasons_are(receiver.on_data(data(0, i == 3 ? 4 : i)), {}));
  EXPECT_TRUE(reasons_are(receiver.on_data(data(0, 7)), {UpdateReason::corrupted}));
  // Data of no accepted block is dropped quietly.
  EXPECT_TRUE(reasons_are(receiver.on_data(data(0, 0)), {}));
  EXPECT_EQ(receiver.received(), 0u);
}

TEST_F(UpdateReceiverTest, TheWindowClosesAtItsSizeAndAcknowledgementsComeEveryFewBlocks) {
  begin(20 * kBlockBytes);
  for (std::uint16_t b = 0; b < kUpdateWindowBlocks; ++b) send_block(b);
  const std::uint16_t next = kUpdateWindowBlocks;
  EXPECT_TRUE(reasons_are(receiver.on_block(header(next, kBlockBytes, block_crc(next, kBlockBytes)), true),
                          {UpdateReason::out_of_order}));
  // Durable one by one: a report after the fourth, then the eighth, which
  // also drains the window.
  for (int b = 1; b <= kUpdateWindowBlocks; ++b) {
    EXPECT_EQ(receiver.waiting_block()[0], image_byte(std::uint32_t(b - 1) * kBlockBytes));
    const bool report = receiver.block_durable();
    EXPECT_EQ(report, b % kUpdateAckEveryBlocks == 0) << "block " << b;
    if (report) receiver.acknowledged();
  }
  EXPECT_FALSE(receiver.block_waiting());
  send_block(next);
  EXPECT_EQ(receiver.received(), std::uint32_t(kUpdateWindowBlocks) + 1);
}

TEST_F(UpdateReceiverTest, AResumedTransferStartsAfterTheBlocksInFlash) {
  receiver.begin(10 * kBlockBytes, 6);
  image_size = 10 * kBlockBytes;
  EXPECT_EQ(receiver.received(), 6u);
  EXPECT_EQ(receiver.durable(), 6u);
  EXPECT_TRUE(reasons_are(receiver.on_block(header(5, kBlockBytes, block_crc(5, kBlockBytes)), true),
                          {UpdateReason::duplicate}));
  send_block(6);
  EXPECT_EQ(receiver.received(), 7u);
  EXPECT_TRUE(receiver.block_durable());  // seven durable, none acknowledged
}

TEST_F(UpdateReceiverTest, NoBlockBeyondTheImage) {
  begin(kBlockBytes);
  send_block(0);
  EXPECT_TRUE(reasons_are(receiver.on_block(header(1, kBlockBytes, block_crc(1, kBlockBytes)), true),
                          {UpdateReason::out_of_order}));
}

}  // namespace
}  // namespace cdcr::firmware
