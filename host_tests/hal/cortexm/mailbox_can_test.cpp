// The QEMU boards' mailbox CAN behaves as a controller does: filters, queue
// limits, frame checks and error counters. Plain C++, so it is checked on the
// host; its use by the runtime is checked on the boards (ctest -L qemu).
#include <gtest/gtest.h>

#include "cdcr/cortexm/mailbox_can.hpp"
#include "cdcr/firmware/protocol/messages.hpp"

namespace cdcr::cortexm {
namespace {

hal::CanFrame frame(std::uint32_t id, std::uint8_t first_byte = 0) {
  hal::CanFrame f;
  f.id = id;
  f.dlc = 1;
  f.data[0] = first_byte;
  return f;
}

TEST(MailboxCan, DeliversInOrderThroughTheFilters) {
  MailboxCan<8, 2> can;
  // The runtime's filters: cable feedback 0x100..0x107, targets 0x120..0x123.
  const hal::CanFilter filters[] = {firmware::protocol::kCableFeedbackFrames, firmware::protocol::kTargetFrames};
  ASSERT_TRUE(can.set_filters(filters, 2));
  for (std::uint32_t id : {0x100u, 0x0FFu, 0x107u, 0x108u, 0x123u, 0x124u}) can.deliver(frame(id));
  hal::CanFrame received;
  for (std::uint32_t expected : {0x100u, 0x107u, 0x123u}) {
    ASSERT_EQ(can.receive(received), hal::CanStatus::ok);
    EXPECT_EQ(received.id, expected);
  }
  EXPECT_EQ(can.receive(received), hal::CanStatus::empty);
}

TEST(MailboxCan, AcceptsEverythingWithoutFiltersAndRefusesTooMany) {
  MailboxCan<8, 2> can;
  const hal::CanFilter filters[3] = {};
  EXPECT_FALSE(can.set_filters(filters, 3));
  can.deliver(frame(0x7FF));
  hal::CanFrame received;
  EXPECT_EQ(can.receive(received), hal::CanStatus::ok);
}

TEST(MailboxCan, CountsOverrunsWhenTheReceiveQueueIsFull) {
  MailboxCan<4, 1> can;
  for (std::uint8_t i = 0; i < 6; ++i) can.deliver(frame(0x100, i));
  EXPECT_EQ(can.error_counters().rx_overruns, 2u);
  hal::CanFrame received;
  for (std::uint8_t i = 0; i < 4; ++i) {
    ASSERT_EQ(can.receive(received), hal::CanStatus::ok);
    EXPECT_EQ(received.data[0], i);  // the oldest kept, the newest lost
  }
}

TEST(MailboxCan, RefusesInvalidFramesAndAFullTransmitQueue) {
  MailboxCan<2, 1> can;
  hal::CanFrame too_long = frame(0x100);
  too_long.dlc = 9;
  EXPECT_EQ(can.send(too_long), hal::CanStatus::invalid_frame);
  EXPECT_EQ(can.send(frame(0x800)), hal::CanStatus::invalid_frame);
  EXPECT_EQ(can.send(frame(0x130, 1)), hal::CanStatus::ok);
  EXPECT_EQ(can.send(frame(0x131, 2)), hal::CanStatus::ok);
  EXPECT_EQ(can.send(frame(0x132, 3)), hal::CanStatus::queue_full);
  EXPECT_EQ(can.error_counters().tx_dropped, 3u);
  hal::CanFrame sent;
  ASSERT_TRUE(can.take_transmitted(sent));
  EXPECT_EQ(sent.id, 0x130u);
  ASSERT_TRUE(can.take_transmitted(sent));
  EXPECT_EQ(sent.id, 0x131u);
  EXPECT_FALSE(can.take_transmitted(sent));
}

}  // namespace
}  // namespace cdcr::cortexm
