// The backend behind the C API: the board steps the runtime itself, so the
// timer only keeps the schedule (a late step is jitter, a step a period or
// more late misses releases); the bus is the board's callbacks or nothing.
#include <gtest/gtest.h>

#include <cdcr/callbacks/callback_hal.hpp>

namespace cdcr::callbacks {
namespace {

struct Board {
  std::int64_t now_ns = 0;
  int send_result = 0;
  int sent = 0;
  cdcr_can_frame inbox{};
  bool has_frame = false;
};

cdcr_callbacks board_callbacks(Board& board) {
  cdcr_callbacks callbacks{};
  callbacks.user = &board;
  callbacks.now_ns = [](void* user) { return static_cast<Board*>(user)->now_ns; };
  callbacks.can_send = [](void* user, const cdcr_can_frame*) {
    Board& b = *static_cast<Board*>(user);
    ++b.sent;
    return b.send_result;
  };
  callbacks.can_receive = [](void* user, cdcr_can_frame* frame) {
    Board& b = *static_cast<Board*>(user);
    if (!b.has_frame) return 0;
    *frame = b.inbox;
    b.has_frame = false;
    return 1;
  };
  return callbacks;
}

TEST(SteppedTimer, TheFirstStepIsReleaseZeroAndLateStepsMissReleases) {
  Board board;
  board.now_ns = 5'000;
  CallbackHal hal(board_callbacks(board), nullptr, 0);
  hal.timer().start(1'000);
  hal::TimerTick tick = hal.timer().wait_next();
  EXPECT_EQ(tick.release_ns, 5'000);
  EXPECT_EQ(tick.missed_releases, 0u);
  board.now_ns = 6'700;  // 700 ns late: jitter, nothing missed
  tick = hal.timer().wait_next();
  EXPECT_EQ(tick.release_ns, 6'000);
  EXPECT_EQ(tick.missed_releases, 0u);
  board.now_ns = 9'500;  // releases 7,000 and 8,000 went by
  tick = hal.timer().wait_next();
  EXPECT_EQ(tick.release_ns, 9'000);
  EXPECT_EQ(tick.missed_releases, 2u);
  EXPECT_EQ(hal.timer().overruns(), 2u);
  // A restart begins a new schedule at the next step.
  hal.timer().start(1'000);
  EXPECT_EQ(hal.timer().overruns(), 0u);
  board.now_ns = 20'000;
  EXPECT_EQ(hal.timer().wait_next().release_ns, 20'000);
}

TEST(SteppedTimer, WithoutAPeriodEveryStepIsItsOwnRelease) {
  Board board;
  CallbackHal hal(board_callbacks(board), nullptr, 0);
  hal.timer().start(0);
  board.now_ns = 123;
  EXPECT_EQ(hal.timer().wait_next().release_ns, 123);
  board.now_ns = 99'999;
  const hal::TimerTick tick = hal.timer().wait_next();
  EXPECT_EQ(tick.release_ns, 99'999);
  EXPECT_EQ(tick.missed_releases, 0u);
  EXPECT_EQ(hal.timer().period_ns(), 0);
}

TEST(CallbackBus, CarriesFramesAndCountsRefusedSends) {
  Board board;
  CallbackHal hal(board_callbacks(board), nullptr, 0);
  hal::CanBus& bus = hal.hal().can;
  hal::CanFrame frame;
  EXPECT_EQ(bus.receive(frame), hal::CanStatus::empty);
  board.inbox.id = 0x123;
  board.inbox.dlc = 12;  // a board's bad length is clamped to a classic frame's
  board.inbox.data[7] = 0xAB;
  board.has_frame = true;
  ASSERT_EQ(bus.receive(frame), hal::CanStatus::ok);
  EXPECT_EQ(frame.id, 0x123u);
  EXPECT_EQ(frame.dlc, 8);
  EXPECT_EQ(frame.data[7], 0xAB);

  EXPECT_EQ(bus.send(frame), hal::CanStatus::ok);
  board.send_result = -1;
  EXPECT_EQ(bus.send(frame), hal::CanStatus::queue_full);
  EXPECT_EQ(board.sent, 2);
  EXPECT_EQ(bus.error_counters().tx_dropped, 1u);
}

TEST(CallbackBus, FiltersOnlyWhereTheBoardReceives) {
  const hal::CanFilter filter{0x100, 0x7F0};
  cdcr_callbacks none{};
  CallbackHal without_bus(none, nullptr, 0);
  EXPECT_TRUE(without_bus.hal().can.set_filters(&filter, 1));  // nothing foreign to filter
  hal::CanFrame frame;
  EXPECT_EQ(without_bus.hal().can.send(frame), hal::CanStatus::ok);  // sent nowhere

  Board board;
  CallbackHal receiving(board_callbacks(board), nullptr, 0);
  EXPECT_FALSE(receiving.hal().can.set_filters(&filter, 1));  // can_receive without can_set_filters
}

TEST(ImageStorage, AnImageWithoutDataIsEmpty) {
  const std::uint8_t image[4] = {1, 2, 3, 4};
  EXPECT_EQ(ImageStorage(image, 4).model_region().size_bytes, 4u);
  EXPECT_EQ(ImageStorage(nullptr, 4).model_region().size_bytes, 0u);
}

}  // namespace
}  // namespace cdcr::callbacks
