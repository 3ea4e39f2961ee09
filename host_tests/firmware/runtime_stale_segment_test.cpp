// Staleness is per segment: a pose needs every segment's cables, so one
// drive falling silent while the others keep reporting every cycle must
// fault the runtime as surely as a silent bus, and its return must recover.

#include <vector>

#include <gtest/gtest.h>

#include "runtime_test_fixture.hpp"

namespace cdcr::firmware {
namespace {

namespace protocol = firmware::protocol;
using test_support::RuntimeTest;

TEST_F(RuntimeTest, OneSilentSegmentFaultsAndItsReturnRecovers) {
  boot(test_support::small_image());
  ASSERT_EQ(runtime->geometry().segment_count, 2);
  cycles(5);
  ASSERT_EQ(runtime->state(), RuntimeState::run);

  drives->set_segment_silent(1, true);
  int cycles_to_fault = 0;
  while (runtime->state() != RuntimeState::fault && cycles_to_fault < 5 * kStaleInputCycles) {
    const std::uint32_t poses_before = runtime->statistics().poses_published;
    cycles(1);
    ++cycles_to_fault;
    // Until the fault, every cycle publishes a pose: no cycle in RUN is
    // silent while the segment's last frames are still within the limit.
    if (runtime->state() == RuntimeState::run) {
      EXPECT_EQ(runtime->statistics().poses_published, poses_before + 1) << "cycle " << cycles_to_fault;
    }
  }
  ASSERT_EQ(runtime->state(), RuntimeState::fault);
  // The segment's frames may be up to kStaleInputCycles old; one more and
  // the input is stale, however fresh the other segment's frames are.
  EXPECT_EQ(cycles_to_fault, kStaleInputCycles + 1);
  EXPECT_EQ(runtime->active_fault(), FaultCode::cable_input_stale);
  EXPECT_EQ(runtime->statistics().stale_events, 1u);

  host_frames();
  const std::uint32_t published = runtime->statistics().poses_published;
  for (int i = 0; i < 3 * kStatusEveryCycles; ++i) {
    cycles(1);
    ASSERT_EQ(runtime->state(), RuntimeState::fault) << "cycle " << i << " after the fault";
  }
  EXPECT_EQ(runtime->statistics().poses_published, published);
  EXPECT_EQ(runtime->statistics().stale_events, 1u);
  protocol::Status status;
  ASSERT_TRUE(last_of(host_frames(), status));
  EXPECT_EQ(status.state, RuntimeState::fault);
  EXPECT_EQ(status.fault, FaultCode::cable_input_stale);

  drives->set_segment_silent(1, false);
  cycles(1);
  EXPECT_EQ(runtime->state(), RuntimeState::run);
  EXPECT_EQ(runtime->active_fault(), FaultCode::none);
  EXPECT_EQ(runtime->statistics().poses_published, published + 1);
  cycles(20);
  EXPECT_EQ(runtime->state(), RuntimeState::run);
  EXPECT_EQ(runtime->statistics().poses_published, published + 21);
}

}  // namespace
}  // namespace cdcr::firmware
