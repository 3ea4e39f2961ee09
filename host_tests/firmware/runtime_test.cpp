// The runtime's state machine and per-cycle behaviour on the simulated
// platform: boot on good and bad images, input validation, stale input,
// inverse kinematics requests.

#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "runtime_fixture.hpp"

namespace cdcr::firmware {
namespace {

namespace protocol = firmware::protocol;
using test_support::SimulatedPlatform;

class RuntimeTest : public ::testing::Test {
 protected:
  void boot(const std::vector<std::uint8_t>& image) {
    platform = std::make_unique<SimulatedPlatform>(image);
    runtime = std::make_unique<Runtime>(platform->hal, Geometry::uniform(2, 120.0f, 67.0f));
    runtime->init();
    drives = std::make_unique<sim::SimulatedCableDrives>(platform->drives_node,
                                                         test_support::bent_cables(runtime->geometry()), 50.0);
    const hal::CanFilter host_filters[] = {{protocol::kIkReportId, 0x7FF}, {protocol::kStatusId, 0x7FE}};
    platform->host_node.set_filters(host_filters, 2);
  }

  void cycles(int count) {
    for (int i = 0; i < count; ++i) {
      const hal::TimerTick tick = platform->timer.wait_next();
      drives->step(1e-3);
      runtime->run_cycle(tick);
    }
  }

  void send(const hal::CanFrame& frame) { ASSERT_EQ(platform->host_node.send(frame), hal::CanStatus::ok); }

  void send_position_target(double x, double y, double z, std::uint8_t sequence) {
    hal::CanFrame frame = protocol::make_frame(protocol::kTargetPositionXyId, 8);
    protocol::put(frame, protocol::signal::position_xy[0], x);
    protocol::put(frame, protocol::signal::position_xy[1], y);
    send(frame);
    frame = protocol::make_frame(protocol::kTargetPositionZId, 6);
    protocol::put(frame, protocol::signal::target_z[0], z);
    protocol::put_raw(frame, protocol::signal::target_z[1], 0);
    protocol::put_raw(frame, protocol::signal::target_z[2], sequence);
    send(frame);
  }

  // The last IK_REPORT frame on the host's node, if any.
  bool last_ik_report(hal::CanFrame& report) {
    bool found = false;
    hal::CanFrame frame;
    while (platform->host_node.receive(frame) == hal::CanStatus::ok) {
      if (frame.id == protocol::kIkReportId) {
        report = frame;
        found = true;
      }
    }
    return found;
  }

  std::unique_ptr<SimulatedPlatform> platform;
  std::unique_ptr<Runtime> runtime;
  std::unique_ptr<sim::SimulatedCableDrives> drives;
};

TEST_F(RuntimeTest, ValidImageBootsIntoRunAndPublishesCompensatedPoses) {
  boot(test_support::small_image());
  EXPECT_EQ(runtime->state(), RuntimeState::run);
  EXPECT_EQ(runtime->active_fault(), FaultCode::none);
  cycles(20);
  EXPECT_EQ(runtime->state(), RuntimeState::run);
  ASSERT_TRUE(runtime->has_pose());
  EXPECT_TRUE(runtime->latest_pose().compensated);
  EXPECT_EQ(runtime->statistics().poses_published, 20u);
  EXPECT_EQ(runtime->statistics().rejected_frames, 0u);
  EXPECT_EQ(runtime->statistics().cycles, 20u);
  EXPECT_EQ(runtime->statistics().overruns, 0u);

  hal::CanFrame frame;
  bool saw_status = false;
  while (platform->host_node.receive(frame) == hal::CanStatus::ok) {
    if (frame.id != protocol::kStatusId) continue;
    saw_status = true;
    EXPECT_EQ(protocol::get_raw(frame, protocol::signal::status[0]), int(RuntimeState::run));
    EXPECT_EQ(protocol::get_raw(frame, protocol::signal::status[1]), int(FaultCode::none));
  }
  EXPECT_TRUE(saw_status);
}

TEST_F(RuntimeTest, CorruptedImageDegradesToNominalKinematics) {
  std::vector<std::uint8_t> image = test_support::small_image();
  image[image.size() / 2] ^= 0x40;
  boot(image);
  EXPECT_EQ(runtime->state(), RuntimeState::degraded);
  EXPECT_EQ(runtime->boot_fault(), FaultCode::image_invalid);
  EXPECT_EQ(runtime->boot_fault_detail(), std::uint8_t(model::ImageStatus::checksum_mismatch));
  EXPECT_EQ(runtime->active_fault(), FaultCode::image_invalid);
  cycles(20);
  EXPECT_EQ(runtime->state(), RuntimeState::degraded);
  ASSERT_TRUE(runtime->has_pose());
  EXPECT_FALSE(runtime->latest_pose().compensated);
}

TEST_F(RuntimeTest, TruncatedImageDegrades) {
  std::vector<std::uint8_t> image = test_support::small_image();
  image.resize(image.size() - 9);
  boot(image);
  EXPECT_EQ(runtime->state(), RuntimeState::degraded);
  EXPECT_EQ(runtime->boot_fault(), FaultCode::image_invalid);
  EXPECT_EQ(runtime->boot_fault_detail(), std::uint8_t(model::ImageStatus::truncated));
  cycles(5);
  EXPECT_TRUE(runtime->has_pose());
}

TEST_F(RuntimeTest, MissingImageDegrades) {
  boot({});
  EXPECT_EQ(runtime->state(), RuntimeState::degraded);
  EXPECT_EQ(runtime->boot_fault(), FaultCode::image_missing);
  EXPECT_EQ(runtime->geometry().segment_count, 2);
}

TEST_F(RuntimeTest, MalformedCableFramesAreCountedAndRejected) {
  boot(test_support::small_image());
  cycles(3);
  const PoseEstimate before = runtime->latest_pose();
  drives->set_silent(true);

  hal::CanFrame short_frame = protocol::make_frame(protocol::kCableFeedbackBaseId, 6);
  send(short_frame);
  hal::CanFrame unavailable = protocol::make_frame(protocol::kCableFeedbackBaseId, 8);
  for (int k = 0; k < 4; ++k) protocol::put_raw(unavailable, protocol::signal::cable[k], 12000);
  protocol::put_raw(unavailable, protocol::signal::cable[1], protocol::kCableNotAvailable);
  send(unavailable);
  hal::CanFrame unknown_segment = unavailable;
  unknown_segment.id = protocol::kCableFeedbackBaseId + 5;  // the image has 2 segments
  protocol::put_raw(unknown_segment, protocol::signal::cable[1], 12000);
  send(unknown_segment);
  cycles(1);

  EXPECT_EQ(runtime->statistics().rejected_frames, 3u);
  EXPECT_EQ(runtime->last_event(), FaultCode::cable_frame_malformed);
  EXPECT_EQ(runtime->active_fault(), FaultCode::cable_frame_malformed);
  EXPECT_EQ(runtime->latest_pose().pose.position_mm, before.pose.position_mm);
  EXPECT_EQ(runtime->state(), RuntimeState::run);
}

TEST_F(RuntimeTest, ImpossibleCableLengthsAreRejected) {
  boot(test_support::small_image());
  cycles(3);
  drives->set_silent(true);
  const std::uint32_t published = runtime->statistics().poses_published;
  // A difference of 390 mm across a 67 mm anchor radius is a bend of 2.9 rad.
  const double impossible_mm[4] = {10.0, 120.0, 400.0, 120.0};
  const double fine_mm[4] = {120.0, 120.0, 120.0, 120.0};
  hal::CanFrame frame;
  ASSERT_TRUE(protocol::encode_cables(protocol::kCableFeedbackBaseId, impossible_mm, frame));
  send(frame);
  ASSERT_TRUE(protocol::encode_cables(protocol::kCableFeedbackBaseId + 1, fine_mm, frame));
  send(frame);
  cycles(1);
  EXPECT_EQ(runtime->statistics().rejected_cable_sets, 1u);
  EXPECT_EQ(runtime->last_event(), FaultCode::cable_lengths_invalid);
  EXPECT_EQ(runtime->statistics().poses_published, published);
}

TEST_F(RuntimeTest, NonFiniteCableLengthsAreRejectedByTheForwardPath) {
  boot(test_support::small_image());
  Cables cables = test_support::bent_cables(runtime->geometry()).cast<Scalar>();
  PoseEstimate estimate;
  ASSERT_EQ(runtime->estimate_pose(cables, estimate), model::Status::ok);
  cables[2] = std::nanf("");
  EXPECT_EQ(runtime->estimate_pose(cables, estimate), model::Status::non_finite_input);
  cables[2] = -5.0f;
  EXPECT_NE(runtime->estimate_pose(cables, estimate), model::Status::ok);
}

TEST_F(RuntimeTest, StaleInputFaultsAndRecovers) {
  boot(test_support::small_image());
  cycles(5);
  drives->set_silent(true);
  cycles(kStaleInputCycles);
  EXPECT_EQ(runtime->state(), RuntimeState::run);
  cycles(1);
  EXPECT_EQ(runtime->state(), RuntimeState::fault);
  EXPECT_EQ(runtime->active_fault(), FaultCode::cable_input_stale);
  EXPECT_EQ(runtime->statistics().stale_events, 1u);
  const std::uint32_t published = runtime->statistics().poses_published;

  hal::CanFrame report;
  last_ik_report(report);
  send_position_target(10, 10, 200, 9);
  cycles(1);
  EXPECT_EQ(runtime->last_ik_report().outcome, protocol::IkOutcome::rejected_state);
  EXPECT_FALSE(runtime->has_setpoints());
  cycles(20);
  EXPECT_EQ(runtime->statistics().poses_published, published);
  EXPECT_EQ(runtime->statistics().stale_events, 1u);

  drives->set_silent(false);
  cycles(1);
  EXPECT_EQ(runtime->state(), RuntimeState::run);
  EXPECT_EQ(runtime->active_fault(), FaultCode::none);
  EXPECT_EQ(runtime->statistics().poses_published, published + 1);
}

TEST_F(RuntimeTest, ReachableTargetPublishesSetpointsAndTheDrivesFollow) {
  boot(test_support::small_image());
  cycles(3);
  const model::Vec3<Scalar> target = runtime->latest_pose().pose.position_mm + model::Vec3<Scalar>(3, -2, 0);
  // Whatever sits in the host queue from boot is not the answer.
  hal::CanFrame report;
  last_ik_report(report);
  send_position_target(target.x(), target.y(), target.z(), 42);
  cycles(1);
  ASSERT_TRUE(last_ik_report(report));
  EXPECT_EQ(protocol::get_raw(report, protocol::signal::ik_report[0]), 42);
  EXPECT_EQ(protocol::get_raw(report, protocol::signal::ik_report[1]), int(protocol::IkOutcome::converged));
  ASSERT_TRUE(runtime->has_setpoints());
  cycles(500);
  EXPECT_LT((runtime->latest_pose().pose.position_mm - target).norm(), 0.05f);
}

TEST_F(RuntimeTest, UnreachableTargetIsReportedAndSetpointsHeld) {
  boot(test_support::small_image());
  cycles(3);
  const model::Vec3<Scalar> reachable = runtime->latest_pose().pose.position_mm + model::Vec3<Scalar>(1, 1, 0);
  send_position_target(reachable.x(), reachable.y(), reachable.z(), 1);
  cycles(1);
  ASSERT_TRUE(runtime->has_setpoints());
  const Cables held = runtime->setpoints_mm();
  cycles(5);
  const std::uint32_t setpoint_frames = drives->setpoint_frames();

  hal::CanFrame report;
  last_ik_report(report);
  send_position_target(900.0, 0.0, 50.0, 2);
  cycles(1);
  ASSERT_TRUE(last_ik_report(report));
  EXPECT_EQ(protocol::get_raw(report, protocol::signal::ik_report[0]), 2);
  EXPECT_EQ(protocol::get_raw(report, protocol::signal::ik_report[1]), int(protocol::IkOutcome::unreachable));
  EXPECT_EQ(runtime->last_ik_report().model_status, model::Status::ik_not_converged);
  EXPECT_EQ(runtime->last_event(), FaultCode::target_unreachable);
  EXPECT_EQ(runtime->setpoints_mm(), held);
  cycles(1);
  EXPECT_EQ(drives->setpoint_frames(), setpoint_frames);
  EXPECT_EQ(runtime->state(), RuntimeState::run);
}

TEST_F(RuntimeTest, TargetWithoutItsPositionFrameIsMalformed) {
  boot(test_support::small_image());
  cycles(3);
  hal::CanFrame frame = protocol::make_frame(protocol::kTargetPositionZId, 6);
  protocol::put_raw(frame, protocol::signal::target_z[2], 7);
  send(frame);
  cycles(1);
  EXPECT_EQ(runtime->last_ik_report().outcome, protocol::IkOutcome::rejected_malformed);
  EXPECT_EQ(runtime->last_event(), FaultCode::target_malformed);
  EXPECT_FALSE(runtime->has_setpoints());
}

TEST(SimulatedPlatform, LockstepTimerReportsMissedReleases) {
  sim::LockstepClock clock;
  sim::LockstepTimer timer(clock);
  timer.start(1000);
  EXPECT_EQ(timer.wait_next().release_ns, 1000);
  EXPECT_EQ(clock.now_ns(), 1000);
  clock.advance_by(2500);  // work ran into the third period
  const hal::TimerTick tick = timer.wait_next();
  EXPECT_EQ(tick.missed_releases, 2u);
  EXPECT_EQ(tick.release_ns, 4000);
  EXPECT_EQ(timer.overruns(), 2u);
}

TEST(SimulatedPlatform, VirtualBusFiltersAndCountsOverruns) {
  sim::VirtualCanBus bus;
  const hal::CanFilter only_0x100{0x100, 0x7FF};
  ASSERT_TRUE(bus.node(1).set_filters(&only_0x100, 1));
  hal::CanFrame frame = protocol::make_frame(0x101, 8);
  EXPECT_EQ(bus.node(0).send(frame), hal::CanStatus::ok);
  frame.id = 0x100;
  for (int i = 0; i < kRxQueueDepth + 3; ++i) bus.node(0).send(frame);
  EXPECT_EQ(bus.node(1).pending(), std::size_t(kRxQueueDepth));
  EXPECT_EQ(bus.node(1).error_counters().rx_overruns, 3u);
  EXPECT_EQ(bus.node(0).pending(), 0u);  // a node does not hear itself
  frame.id = 0x800;
  EXPECT_EQ(bus.node(0).send(frame), hal::CanStatus::invalid_frame);
  hal::CanFrame received;
  EXPECT_EQ(bus.node(1).receive(received), hal::CanStatus::ok);
  EXPECT_EQ(received.id, 0x100u);
}

}  // namespace
}  // namespace cdcr::firmware
