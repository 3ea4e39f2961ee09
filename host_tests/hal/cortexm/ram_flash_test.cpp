// The QEMU boards' RAM flash: NOR semantics, busy polls, ranges, and the
// slot layout and a committed image on it as the runtime reads them.

#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/cortexm/ram_flash.hpp>
#include <cdcr/firmware/model_slots.hpp>

namespace cdcr::cortexm {
namespace {

using Flash = RamFlash<512, 8, 64>;

void wait_done(Flash& flash) {
  int polls = 0;
  while (flash.poll() == hal::FlashStatus::busy) ++polls;
  EXPECT_LE(polls, int(Flash::kErasePolls));
}

TEST(RamFlash, StartsErasedProgramsClearBitsAndEraseRestores) {
  static Flash flash;
  for (std::uint32_t i = 0; i < flash.size_bytes(); ++i) ASSERT_EQ(flash.read()[i], 0xFF);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(flash.read()) % 8, 0u);
  const std::uint8_t a[2] = {0xF0, 0x0F};
  const std::uint8_t b[2] = {0x3C, 0xFF};
  ASSERT_EQ(flash.start_program(600, a, 2), hal::FlashStatus::ok);
  EXPECT_EQ(flash.start_program(600, b, 2), hal::FlashStatus::busy);
  EXPECT_EQ(flash.poll(), hal::FlashStatus::busy);
  wait_done(flash);
  ASSERT_EQ(flash.start_program(600, b, 2), hal::FlashStatus::ok);
  wait_done(flash);
  EXPECT_EQ(flash.read()[600], 0x30);
  EXPECT_EQ(flash.read()[601], 0x0F);
  ASSERT_EQ(flash.start_erase(1), hal::FlashStatus::ok);
  EXPECT_EQ(flash.poll(), hal::FlashStatus::busy);
  wait_done(flash);
  EXPECT_EQ(flash.read()[600], 0xFF);
}

TEST(RamFlash, RefusesWhatAFlashRefuses) {
  static Flash flash;
  const std::uint8_t data[65] = {};
  EXPECT_EQ(flash.start_erase(8), hal::FlashStatus::bad_range);
  EXPECT_EQ(flash.start_program(500, data, 16), hal::FlashStatus::bad_range);  // across sectors
  EXPECT_EQ(flash.start_program(0, data, 65), hal::FlashStatus::bad_range);    // longer than a program
  EXPECT_EQ(flash.start_program(4096, data, 1), hal::FlashStatus::bad_range);
  EXPECT_EQ(flash.start_program(0, data, 0), hal::FlashStatus::bad_range);
}

TEST(RamFlash, HoldsTwoSlots) {
  static Flash flash;
  const firmware::SlotGeometry a = firmware::slot_geometry(flash, 0);
  const firmware::SlotGeometry b = firmware::slot_geometry(flash, 1);
  EXPECT_EQ(a.sectors, 4u);
  EXPECT_EQ(b.offset, 4u * 512u);
  EXPECT_EQ(a.image_capacity(), 3u * 512u);
  firmware::SlotImage found[firmware::kModelSlots];
  EXPECT_EQ(firmware::committed_slots(flash, found), 0);
}

}  // namespace
}  // namespace cdcr::cortexm
