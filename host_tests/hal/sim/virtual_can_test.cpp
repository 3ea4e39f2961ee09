// The simulated bus: delivery to every other node through its filters, the
// receive queue's depth, invalid frames and a node off the bus; timed, a
// frame's time on the wire, arbitration and the transmit queue.
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/sim/lockstep_timer.hpp>
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

hal::CanFrame frame_of(std::uint32_t id, std::initializer_list<std::uint8_t> bytes) {
  hal::CanFrame f;
  f.id = id;
  for (const std::uint8_t b : bytes) f.data[f.dlc++] = b;
  return f;
}

struct Recorder final : CanTransferObserver {
  void on_transfer(const CanTransfer& transfer) override { seen.push_back(transfer); }
  std::vector<CanTransfer> seen;
};

// 0x123 with 12 34: 64 bits with its one stuff bit and the interframe
// space (written out bit by bit in host_tests/hal/can_timing_test.cpp).
constexpr std::int64_t k0x123At1Mbit = 64000;

TEST(TimedVirtualCanBus, DeliversAFrameWhenItsLastBitHasPassed) {
  VirtualCanBus bus;
  LockstepClock clock;
  clock.advance_to(5000);
  bus.set_timing(clock, {1000000, 0});
  Recorder recorder;
  bus.set_observer(&recorder);
  ASSERT_EQ(bus.node(0).send(frame_of(0x123, {0x12, 0x34})), hal::CanStatus::ok);
  EXPECT_EQ(bus.node(0).transmit_pending(), 1u);
  hal::CanFrame received;
  EXPECT_EQ(bus.node(1).receive(received), hal::CanStatus::empty);  // still at the instant it was sent
  clock.advance_to(5000 + k0x123At1Mbit - 1);
  EXPECT_EQ(bus.node(1).receive(received), hal::CanStatus::empty);
  clock.advance_to(5000 + k0x123At1Mbit);
  ASSERT_EQ(bus.node(1).receive(received), hal::CanStatus::ok);
  EXPECT_EQ(received.id, 0x123u);
  EXPECT_EQ(received.data[1], 0x34);
  ASSERT_EQ(recorder.seen.size(), 1u);
  EXPECT_EQ(recorder.seen[0].queued_ns, 5000);
  EXPECT_EQ(recorder.seen[0].start_ns, 5000);
  EXPECT_EQ(recorder.seen[0].end_ns, 5000 + k0x123At1Mbit);
  EXPECT_EQ(recorder.seen[0].sender, 0);
  EXPECT_EQ(bus.busy_ns(), k0x123At1Mbit);
  // At half the rate, twice the time.
  VirtualCanBus slow;
  LockstepClock slow_clock;
  slow.set_timing(slow_clock, {500000, 0});
  slow.node(0).send(frame_of(0x123, {0x12, 0x34}));
  slow_clock.advance_to(2 * k0x123At1Mbit - 1);
  EXPECT_EQ(slow.node(1).receive(received), hal::CanStatus::empty);
  slow_clock.advance_to(2 * k0x123At1Mbit);
  EXPECT_EQ(slow.node(1).receive(received), hal::CanStatus::ok);
}

TEST(TimedVirtualCanBus, TheLowerIdentifierWinsArbitrationWhateverTheOrderOfSending) {
  VirtualCanBus bus;
  LockstepClock clock;
  bus.set_timing(clock, {1000000, 0});
  Recorder recorder;
  bus.set_observer(&recorder);
  // Node 0's frame has the bus; while it is on the wire nodes 1 and 2 queue
  // behind it, the higher identifier first.
  bus.node(0).send(frame_of(0x300, {1}));
  clock.advance_to(10000);
  bus.node(1).send(frame_of(0x200, {2}));
  clock.advance_to(20000);
  bus.node(2).send(frame_of(0x100, {3}));
  clock.advance_to(1000000);
  bus.catch_up();
  ASSERT_EQ(recorder.seen.size(), 3u);
  EXPECT_EQ(recorder.seen[0].frame.id, 0x300u);
  EXPECT_EQ(recorder.seen[1].frame.id, 0x100u);  // queued last, sent first
  EXPECT_EQ(recorder.seen[2].frame.id, 0x200u);
  EXPECT_EQ(recorder.seen[1].start_ns, recorder.seen[0].end_ns);  // the interframe space is in end_ns
  EXPECT_EQ(recorder.seen[2].start_ns, recorder.seen[1].end_ns);
  EXPECT_EQ(recorder.seen[2].queued_ns, 10000);
  // Sent at the same instant onto an idle bus: the lower identifier, though
  // its node sent second.
  bus.node(1).send(frame_of(0x181, {}));
  bus.node(2).send(frame_of(0x180, {}));
  clock.advance_to(2000000);
  bus.catch_up();
  ASSERT_EQ(recorder.seen.size(), 5u);
  EXPECT_EQ(recorder.seen[3].frame.id, 0x180u);
  EXPECT_EQ(recorder.seen[3].start_ns, 1000000);
  EXPECT_EQ(recorder.seen[4].frame.id, 0x181u);
  // Every receiver but the sender has each frame, in the order of the wire.
  hal::CanFrame received;
  std::vector<std::uint32_t> order;
  while (bus.node(3).receive(received) == hal::CanStatus::ok) order.push_back(received.id);
  EXPECT_EQ(order, (std::vector<std::uint32_t>{0x300, 0x100, 0x200, 0x180, 0x181}));
  EXPECT_EQ(bus.node(2).pending(), 3u);
}

TEST(TimedVirtualCanBus, ANodeSendsItsOwnFramesInOrderAndBackToBack) {
  VirtualCanBus bus;
  LockstepClock clock;
  bus.set_timing(clock, {1000000, 0});
  Recorder recorder;
  bus.set_observer(&recorder);
  // A controller's FIFO: its own queue is not reordered by identifier.
  bus.node(0).send(frame_of(0x123, {0x12, 0x34}));
  bus.node(0).send(frame_of(0x101, {0x12, 0x34}));
  bus.node(0).send(frame_of(0x123, {0x12, 0x34}));
  clock.advance_to(1000000);
  bus.catch_up();
  ASSERT_EQ(recorder.seen.size(), 3u);
  EXPECT_EQ(recorder.seen[0].frame.id, 0x123u);
  EXPECT_EQ(recorder.seen[1].frame.id, 0x101u);
  EXPECT_EQ(recorder.seen[2].start_ns, recorder.seen[1].end_ns);
  EXPECT_EQ(recorder.seen[2].end_ns - recorder.seen[2].start_ns, k0x123At1Mbit);
  EXPECT_EQ(bus.busy_ns(), recorder.seen[2].end_ns);  // no idle time between them
}

TEST(TimedVirtualCanBus, AFullTransmitQueueRefusesTheFrame) {
  VirtualCanBus bus;
  LockstepClock clock;
  bus.set_timing(clock, {1000000, 0});
  for (std::size_t i = 0; i < VirtualCanNode::kTxQueueDepth; ++i) {
    ASSERT_EQ(bus.node(0).send(frame_of(0x100, {})), hal::CanStatus::ok);
  }
  EXPECT_EQ(bus.node(0).send(frame_of(0x100, {})), hal::CanStatus::queue_full);
  EXPECT_EQ(bus.node(0).error_counters().tx_dropped, 1u);
  // Once one has gone on the wire there is room again.
  clock.advance_to(1);
  bus.catch_up();
  EXPECT_EQ(bus.node(0).send(frame_of(0x100, {})), hal::CanStatus::ok);
}

}  // namespace
}  // namespace cdcr::sim
