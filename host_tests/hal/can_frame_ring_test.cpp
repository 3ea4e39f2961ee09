// The fixed-capacity frame ring and the software acceptance filters that the
// simulated bus and the boards' mailbox share.
#include <cstdint>

#include <gtest/gtest.h>

#include <cdcr/hal/can_filter_bank.hpp>
#include <cdcr/hal/can_frame_ring.hpp>

namespace cdcr::hal {
namespace {

CanFrame frame(std::uint32_t id, std::uint8_t first_byte = 0) {
  CanFrame f;
  f.id = id;
  f.dlc = 1;
  f.data[0] = first_byte;
  return f;
}

TEST(CanFrameRing, KeepsTheOldestFramesInOrderAcrossTheWrap) {
  CanFrameRing<3> ring;
  CanFrame out;
  EXPECT_FALSE(ring.pop(out));
  for (std::uint8_t round = 0; round < 4; ++round) {  // head walks around the storage
    EXPECT_TRUE(ring.push(frame(0x100, std::uint8_t(3 * round))));
    EXPECT_TRUE(ring.push(frame(0x100, std::uint8_t(3 * round + 1))));
    ASSERT_TRUE(ring.pop(out));
    EXPECT_EQ(out.data[0], 3 * round);
    ASSERT_TRUE(ring.pop(out));
    EXPECT_EQ(out.data[0], 3 * round + 1);
  }
  EXPECT_EQ(ring.size(), 0u);
}

TEST(CanFrameRing, RefusesAFrameWhenFull) {
  CanFrameRing<2> ring;
  EXPECT_TRUE(ring.push(frame(0x100, 1)));
  EXPECT_TRUE(ring.push(frame(0x100, 2)));
  EXPECT_FALSE(ring.push(frame(0x100, 3)));
  EXPECT_EQ(ring.size(), ring.capacity());
  CanFrame out;
  ASSERT_TRUE(ring.pop(out));
  EXPECT_EQ(out.data[0], 1);  // the newest was dropped, not the oldest
}

TEST(CanFilterBank, AcceptsEverythingUntilFiltersAreSet) {
  CanFilterBank<2> filters;
  EXPECT_TRUE(filters.accepts(0x000));
  EXPECT_TRUE(filters.accepts(0x7FF));
  const CanFilter block{0x100, 0x7F8};  // 0x100..0x107
  ASSERT_TRUE(filters.assign(&block, 1));
  EXPECT_TRUE(filters.accepts(0x100));
  EXPECT_TRUE(filters.accepts(0x107));
  EXPECT_FALSE(filters.accepts(0x108));
  ASSERT_TRUE(filters.assign(nullptr, 0));
  EXPECT_TRUE(filters.accepts(0x108));
}

TEST(CanFilterBank, RefusesMoreFiltersThanItHoldsAndKeepsTheOldOnes) {
  CanFilterBank<1> filters;
  const CanFilter one{0x100, 0x7FF};
  ASSERT_TRUE(filters.assign(&one, 1));
  const CanFilter two[2] = {{0x200, 0x7FF}, {0x300, 0x7FF}};
  EXPECT_FALSE(filters.assign(two, 2));
  EXPECT_TRUE(filters.accepts(0x100));
  EXPECT_FALSE(filters.accepts(0x200));
}

TEST(CanFrame, ValidMeansAStandardIdAndAtMostEightBytes) {
  EXPECT_TRUE(is_valid(frame(0x7FF)));
  EXPECT_FALSE(is_valid(frame(0x800)));
  CanFrame nine = frame(0x100);
  nine.dlc = 9;
  EXPECT_FALSE(is_valid(nine));
}

}  // namespace
}  // namespace cdcr::hal
