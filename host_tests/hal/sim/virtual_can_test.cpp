// The simulated bus: delivery to every other node through its filters, the
// receive queue's depth, invalid frames and a node off the bus.
#include <gtest/gtest.h>

#include <cdcr/sim/virtual_can.hpp>

namespace cdcr::sim {
namespace {

TEST(VirtualCanBus, FiltersAndCountsOverruns) {
  VirtualCanBus bus;
  const hal::CanFilter only_0x100{0x100, 0x7FF};
  ASSERT_TRUE(bus.node(1).set_filters(&only_0x100, 1));
  hal::CanFrame frame;
  frame.id = 0x101;
  frame.dlc = 8;
  EXPECT_EQ(bus.node(0).send(frame), hal::CanStatus::ok);
  frame.id = 0x100;
  for (std::size_t i = 0; i < VirtualCanNode::kRxQueueDepth + 3; ++i) bus.node(0).send(frame);
  EXPECT_EQ(bus.node(1).pending(), VirtualCanNode::kRxQueueDepth);
  EXPECT_EQ(bus.node(1).error_counters().rx_overruns, 3u);
  EXPECT_EQ(bus.node(0).pending(), 0u);  // a node does not hear itself
  frame.id = 0x800;
  EXPECT_EQ(bus.node(0).send(frame), hal::CanStatus::invalid_frame);
  hal::CanFrame received;
  EXPECT_EQ(bus.node(1).receive(received), hal::CanStatus::ok);
  EXPECT_EQ(received.id, 0x100u);
}

TEST(VirtualCanBus, ANodeOffTheBusSendsNothing) {
  VirtualCanBus bus;
  hal::CanFrame frame;
  frame.id = 0x100;
  bus.node(0).set_bus_off(true);
  EXPECT_EQ(bus.node(0).send(frame), hal::CanStatus::bus_off);
  EXPECT_EQ(bus.node(0).error_counters().tx_dropped, 1u);
  EXPECT_EQ(bus.node(1).pending(), 0u);
  bus.node(0).set_bus_off(false);
  EXPECT_EQ(bus.node(0).send(frame), hal::CanStatus::ok);
  EXPECT_EQ(bus.node(1).pending(), 1u);
  EXPECT_EQ(bus.node(2).pending(), 1u);
}

}  // namespace
}  // namespace cdcr::sim
