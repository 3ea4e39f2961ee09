// The slot writer on its own, over a simulated NOR flash of 8 sectors of
// 4 KiB: slot A is sectors 0-3 (metadata at 0, image from 4096, header at
// 4032), slot B sectors 4-7 (metadata at 16384). Every operation is started
// by hand and its bytes are looked for at the offsets model_slots.hpp gives.

#include <cstdint>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/firmware/update/slot_writer.hpp>
#include <cdcr/sim/sim_flash.hpp>

#include "model_update_fixture.hpp"

namespace cdcr::firmware {
namespace {

constexpr std::uint32_t kSector = 4096;
constexpr std::uint32_t kSlotB = 4 * kSector;
constexpr std::uint32_t kHeaderA = kSector - kSlotHeaderBytes;
constexpr std::uint32_t kImageA = kSector;

hal::FlashStatus finish(SlotWriter& writer) {
  hal::FlashStatus status;
  while ((status = writer.poll()) == hal::FlashStatus::busy) {
  }
  return status;
}

class SlotWriterTest : public ::testing::Test {
 protected:
  void SetUp() { std::memset(flash.raw(), 0xFF, 8 * kSector); }

  sim::SimFlash flash{kSector, 8};
  SlotWriter writer{&flash};
  std::uint8_t digest[kSha256Bytes] = {};
};

TEST(SlotWriterUsable, NeedsTwoSlotsAndWholeRecordPrograms) {
  sim::SimFlash two_slots(4096, 4);
  EXPECT_TRUE(SlotWriter(&two_slots).usable());
  sim::SimFlash one_sector_a_slot(4096, 3);
  EXPECT_FALSE(SlotWriter(&one_sector_a_slot).usable());
  sim::SimFlash short_programs(4096, 4, kSlotRecordBytes - 1);
  EXPECT_FALSE(SlotWriter(&short_programs).usable());
  EXPECT_FALSE(SlotWriter(nullptr).usable());
}

TEST_F(SlotWriterTest, ATransferGoesToTheSlotThatDoesNotRun) {
  writer.boot();
  EXPECT_EQ(writer.candidate_count(), 0);
  writer.set_active(-1);
  writer.target_other_slot();
  EXPECT_EQ(writer.target_slot(), 0);
  EXPECT_EQ(writer.target_image(), flash.read() + kImageA);
  // 12 KiB of image, 4096 - 128 progress bytes.
  EXPECT_TRUE(writer.fits(3 * kSector, kSector - 128));
  EXPECT_FALSE(writer.fits(3 * kSector + 1, 10));
  EXPECT_FALSE(writer.fits(100, kSector - 127));
}

TEST_F(SlotWriterTest, TheRecordBlocksAndHeaderLandWhereTheSlotLayoutSays) {
  writer.boot();
  writer.target_other_slot();
  for (std::uint32_t i = 0; i < kSha256Bytes; ++i) digest[i] = static_cast<std::uint8_t>(i + 1);
  writer.new_record(0x1234, 100, digest);
  std::memset(flash.raw(), 0x00, kSector);  // the erase must show
  ASSERT_EQ(writer.start_erase_metadata(), hal::FlashStatus::ok);
  EXPECT_TRUE(writer.operation_running());
  EXPECT_EQ(writer.start_write_record(), hal::FlashStatus::busy);  // one operation at a time
  ASSERT_EQ(finish(writer), hal::FlashStatus::ok);
  EXPECT_FALSE(writer.operation_running());
  for (std::uint32_t i = 0; i < kSector; ++i) ASSERT_EQ(flash.read()[i], 0xFF) << i;

  ASSERT_EQ(writer.start_write_record(), hal::FlashStatus::ok);
  ASSERT_EQ(finish(writer), hal::FlashStatus::ok);
  TransferRecord in_flash;
  ASSERT_TRUE(decode_record(flash.read(), in_flash));
  EXPECT_EQ(in_flash.transfer_id, 0x1234);
  EXPECT_EQ(in_flash.image_size, 100u);
  EXPECT_EQ(std::memcmp(in_flash.digest, digest, kSha256Bytes), 0);
  writer.forget_record();
  writer.read_record();
  EXPECT_TRUE(writer.record_in_flash());

  // 100 bytes: one image sector, the slot's second.
  writer.erase_image_from_start();
  EXPECT_FALSE(writer.image_erased());
  flash.raw()[kImageA] = 0x00;
  ASSERT_EQ(writer.start_erase_image_sector(), hal::FlashStatus::ok);
  ASSERT_EQ(finish(writer), hal::FlashStatus::ok);
  EXPECT_EQ(flash.read()[kImageA], 0xFF);
  writer.image_sector_erased();
  EXPECT_TRUE(writer.image_erased());

  // Block 1 (bytes 64..99) before block 0: its data, then its progress byte.
  const std::uint8_t block[36] = {0xA5, 0x5A, 0x0F};
  ASSERT_EQ(writer.start_block_data(1, block, 36), hal::FlashStatus::ok);
  ASSERT_EQ(finish(writer), hal::FlashStatus::ok);
  EXPECT_FALSE(writer.block_step_done());
  EXPECT_TRUE(writer.block_data_written());
  EXPECT_EQ(std::memcmp(flash.read() + kImageA + 64, block, 36), 0);
  ASSERT_EQ(writer.start_block_progress(1), hal::FlashStatus::ok);
  ASSERT_EQ(finish(writer), hal::FlashStatus::ok);
  EXPECT_TRUE(writer.block_step_done());
  EXPECT_FALSE(writer.block_pending());
  EXPECT_EQ(flash.read()[kSlotRecordBytes + 1], 0x00);
  EXPECT_EQ(writer.blocks_in_flash(2), 0u);  // counted from the first
  ASSERT_EQ(writer.start_block_progress(0), hal::FlashStatus::ok);
  ASSERT_EQ(finish(writer), hal::FlashStatus::ok);
  EXPECT_EQ(writer.blocks_in_flash(2), 2u);
  EXPECT_EQ(writer.blocks_in_flash(1), 1u);

  ASSERT_EQ(writer.start_write_header(), hal::FlashStatus::ok);
  ASSERT_EQ(finish(writer), hal::FlashStatus::ok);
  SlotHeader header;
  ASSERT_TRUE(decode_header(flash.read() + kHeaderA, header));
  EXPECT_EQ(header.sequence, 1u);
  EXPECT_EQ(header.image_size, 100u);
  EXPECT_EQ(std::memcmp(header.digest, digest, kSha256Bytes), 0);
  EXPECT_EQ(writer.header_written(model::ImageScan{}), 0);
  ASSERT_EQ(writer.candidate_count(), 1);
  EXPECT_EQ(writer.candidate(0).slot, 0);
  EXPECT_EQ(writer.candidate(0).sequence, 1u);
  EXPECT_EQ(writer.candidate(0).region.size_bytes, 100u);
  EXPECT_FALSE(writer.record_in_flash());
}

TEST_F(SlotWriterTest, TheCommitNumbersAboveTheRunningImageAndKeepsItAsFallback) {
  const std::vector<std::uint8_t> image = test_support::small_image();
  // Slot A holds an older transfer's header, numbered high: the new header
  // replaces it, so it does not count.
  test_support::provision_slot(flash, 0, image, 20);
  test_support::provision_slot(flash, 1, image, 7);
  writer.boot();
  ASSERT_EQ(writer.candidate_count(), 2);
  EXPECT_EQ(writer.candidate(0).slot, 0);  // newest first
  writer.set_active(1);
  EXPECT_EQ(writer.active_slot(), 1);
  EXPECT_EQ(writer.active_sequence(), 7u);
  writer.target_other_slot();
  EXPECT_EQ(writer.target_slot(), 0);
  writer.new_record(1, static_cast<std::uint32_t>(image.size()), digest);
  ASSERT_EQ(writer.start_write_header(), hal::FlashStatus::ok);
  ASSERT_EQ(finish(writer), hal::FlashStatus::ok);
  EXPECT_EQ(writer.header_written(model::ImageScan{}), 0);
  ASSERT_EQ(writer.candidate_count(), 2);
  EXPECT_EQ(writer.candidate(0).slot, 0);
  EXPECT_EQ(writer.candidate(0).sequence, 8u);
  EXPECT_EQ(writer.candidate(1).slot, 1);
  EXPECT_EQ(writer.candidate(1).sequence, 7u);
}

TEST_F(SlotWriterTest, ARevokedImageIsNoCandidate) {
  const std::vector<std::uint8_t> image = test_support::small_image();
  test_support::provision_slot(flash, 0, image, 3);
  test_support::provision_slot(flash, 1, image, 4);
  writer.boot();
  ASSERT_EQ(writer.candidate_count(), 2);
  ASSERT_EQ(writer.start_revoke(1), hal::FlashStatus::ok);
  ASSERT_EQ(finish(writer), hal::FlashStatus::ok);
  for (std::uint32_t i = 0; i < 4; ++i) EXPECT_EQ(flash.read()[kSlotB + kSector - 4 + i], 0x00);
  SlotHeader header;
  EXPECT_FALSE(read_slot_header(flash, 1, header));
  EXPECT_TRUE(read_slot_header(flash, 0, header));
  writer.drop_candidate(1);
  ASSERT_EQ(writer.candidate_count(), 1);
  EXPECT_EQ(writer.candidate(0).slot, 0);

  // A rollback makes slot A's image the only one, read in place.
  ASSERT_TRUE(read_slot_header(flash, 0, header));
  writer.make_only_candidate(0, header, model::ImageScan{});
  ASSERT_EQ(writer.candidate_count(), 1);
  EXPECT_EQ(writer.candidate(0).sequence, 3u);
  EXPECT_EQ(writer.candidate(0).region.data, flash.read() + kImageA);
  EXPECT_EQ(writer.candidate(0).region.size_bytes, image.size());
}

}  // namespace
}  // namespace cdcr::firmware
