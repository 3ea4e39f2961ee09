// After init the runtime never reaches the heap: 10,000 cycles of feedback
// decoding, compensated forward kinematics, publishing, a compensated IK
// request and a stale-input fault and recovery, all under the counter.

#include <memory>

#include <gtest/gtest.h>

#include "allocation_counter.hpp"
#include "runtime_fixture.hpp"

namespace cdcr::firmware {
namespace {

namespace protocol = firmware::protocol;

TEST(RuntimeNoAllocation, TenThousandCyclesAfterInit) {
  test_support::SimulatedPlatform platform(test_support::small_image());
  // The recording console keeps std::strings; a board's UART does not allocate.
  sim::StderrConsole silent_console(false);
  const hal::Hal hal{platform.clock, platform.timer, platform.bus.node(0), platform.storage, silent_console};
  Runtime runtime(hal, Geometry::uniform(2, 120.0f, 67.0f));
  ASSERT_EQ(runtime.init(), RuntimeState::run);
  sim::SimulatedCableDrives drives(platform.drives_node, test_support::bent_cables(runtime.geometry()), 50.0);
  const hal::CanFilter nothing{0x7FF, 0x7FF};  // an identifier no node sends: the host's queue stays empty
  platform.host_node.set_filters(&nothing, 1);

  test_support::AllocationCounter counter;
  for (int k = 0; k < 10000; ++k) {
    if (k == 100) {
      const model::Vec3<double> position = runtime.latest_pose().pose.position_mm.cast<double>();
      hal::CanFrame frame;
      protocol::encode(protocol::TargetPositionXy{position.x() + 2, position.y()}, frame);
      platform.host_node.send(frame);
      protocol::encode(protocol::TargetPositionZ{position.z(), protocol::TargetMode::position, false, 0}, frame);
      platform.host_node.send(frame);
    }
    drives.set_silent(k >= 5000 && k < 5050);
    const hal::TimerTick tick = platform.timer.wait_next();
    drives.step(1e-3);
    runtime.run_cycle(tick);
  }
  counter.stop();

  EXPECT_EQ(counter.operator_new_calls(), 0);
  EXPECT_EQ(counter.malloc_calls(), 0);
  EXPECT_EQ(runtime.statistics().cycles, 10000u);
  EXPECT_EQ(runtime.statistics().targets_received, 1u);
  EXPECT_EQ(runtime.last_ik_report().outcome, protocol::IkOutcome::converged);
  EXPECT_EQ(runtime.statistics().stale_events, 1u);
  EXPECT_EQ(runtime.state(), RuntimeState::run);
}

}  // namespace
}  // namespace cdcr::firmware
