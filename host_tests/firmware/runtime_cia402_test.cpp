// The runtime with its cable drives behind the CiA 402 backend (hal::Drives,
// firmware/canopen): the four-segment robot's 16 drives on two buses,
// started from power-up to RUN, the pose estimated from their positions,
// a target's setpoints reached, and a drive's faults reported in STATUS
// with its node id and recovered on command.

#include <algorithm>
#include <cmath>
#include <string>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/firmware/canopen/cia402_drives.hpp>
#include <cdcr/firmware/runtime.hpp>

#include "cia402_test_drive.hpp"
#include "runtime_fixture.hpp"

namespace cdcr::firmware::canopen {
namespace {

constexpr double kCountsPerMm = 2000.0;

class RuntimeCia402Test : public ::testing::Test {
 protected:
  void SetUp() override {
    platform_ = std::make_unique<test_support::SimulatedPlatform>(test_support::small_image());
    // The image's robot, to learn its cable count and a bent pose's lengths.
    Runtime probe(platform_->hal, Geometry::prototype());
    probe.init();
    cables_ = probe.geometry().cable_count();
    const auto start_mm = test_support::bent_cables(probe.geometry());
    config_.drive_count = cables_;
    config_.bus_count = 2;
    config_.timing = {1000, 500, 20};
    config_.max_speed_mm_per_s = 50.0;
    for (int i = 0; i < cables_; ++i) {
      // Half the cables on each bus, node ids from 1 on each; every other
      // drive counts down for a longer cable; homed at 100 mm.
      const double sign = (i % 2) ? -1.0 : 1.0;
      config_.drives[i] = {std::uint8_t(i * 2 / cables_), NodeId(i % (cables_ / 2) + 1), sign * kCountsPerMm, 100.0};
      drives_[i].node = config_.drives[i].node;
      drives_[i].position = std::round((start_mm[i] - 100.0) * sign * kCountsPerMm);
    }
  }

  void make_runtime() {
    backend_ = std::make_unique<Cia402Drives>(config_, buses_);
    hal::Hal hal = platform_->hal;
    hal.drives = backend_.get();
    runtime_ = std::make_unique<Runtime>(hal, Geometry::prototype());
    runtime_->init();
  }

  void cycle() {
    const hal::TimerTick tick = platform_->timer.wait_next();
    runtime_->run_cycle(tick);
    hal::CanFrame frame;
    for (int b = 0; b < 2; ++b) {
      while (drive_bus_[b].node(1).receive(frame) == hal::CanStatus::ok)
        for (int i = 0; i < cables_; ++i)
          if (config_.drives[i].bus == b) drives_[i].take(frame, drive_bus_[b].node(1));
      for (int i = 0; i < cables_; ++i)
        if (config_.drives[i].bus == b) drives_[i].tick(drive_bus_[b].node(1));
    }
  }
  int cycles_until(RuntimeState state, int limit) {
    for (int n = 1; n <= limit; ++n) {
      cycle();
      if (runtime_->state() == state) return n;
    }
    return -1;
  }
  // From power-up until the drives are enabled and the runtime has its pose
  // of them (it enters RUN at init, and FAULT while no lengths come).
  int start_drives(int limit = 1000) {
    for (int n = 1; n <= limit; ++n) {
      cycle();
      if (runtime_->drives_health().condition == hal::DrivesCondition::ready && runtime_->state() == RuntimeState::run &&
          runtime_->has_pose())
        return n;
    }
    return -1;
  }
  // The lengths the drives' positions say, as the test reads them.
  Cables drive_lengths() const {
    Cables lengths;
    lengths.setZero(cables_);
    for (int i = 0; i < cables_; ++i)
      lengths[i] = Scalar(std::trunc(drives_[i].position) / config_.drives[i].counts_per_mm + 100.0);
    return lengths;
  }

  std::unique_ptr<test_support::SimulatedPlatform> platform_;
  sim::VirtualCanBus drive_bus_[2];
  hal::CanBus* const buses_[kMaxDriveBuses] = {&drive_bus_[0].node(0), &drive_bus_[1].node(0), nullptr, nullptr};
  DriveManagerConfig config_;
  TestDrive drives_[kMaxDrives];
  int cables_ = 0;
  std::unique_ptr<Cia402Drives> backend_;
  std::unique_ptr<Runtime> runtime_;
};

TEST_F(RuntimeCia402Test, FromPowerUpToRunWithThePoseOfTheDrivesPositions) {
  make_runtime();
  ASSERT_GE(cables_, 8);
  // Before the drives are enabled the runtime has no lengths: FAULT, stale.
  for (int n = 0; n < 20; ++n) cycle();
  EXPECT_EQ(runtime_->state(), RuntimeState::fault);
  EXPECT_EQ(runtime_->active_fault(), FaultCode::cable_input_stale);
  EXPECT_EQ(runtime_->drives_health().condition, hal::DrivesCondition::starting);
  const int cycles = start_drives();
  ASSERT_GT(cycles, 0) << backend_->describe(runtime_->drives_health().kind);
  // 18 configuration writes for each of 8 drives a bus, 4 requests a cycle.
  EXPECT_LT(cycles, 100);
  for (int n = 0; n < 5; ++n) cycle();
  // The pose of the lengths the drives reported (positions of the SYNC
  // before this cycle's: they do not move while no setpoint is given).
  PoseEstimate expected;
  ASSERT_EQ(runtime_->estimate_pose(drive_lengths(), expected), model::Status::ok);
  EXPECT_NEAR((runtime_->latest_pose().pose.position_mm - expected.pose.position_mm).norm(), 0.0, 1e-4);
  for (const auto& drive : drives_) {
    if (drive.node == 0) continue;
    EXPECT_EQ(drive.objects.at(0x606000), 8u);
  }
}

TEST_F(RuntimeCia402Test, TargetSetpointsReachTheDrives) {
  make_runtime();
  ASSERT_GT(start_drives(), 0);
  for (int n = 0; n < 5; ++n) cycle();
  const auto start = runtime_->latest_pose().pose.position_mm;
  TargetRequest target;
  target.position_mm[0] = double(start.x()) + 2.0;
  target.position_mm[1] = double(start.y()) - 1.0;
  target.position_mm[2] = double(start.z());
  target.sequence = 7;
  runtime_->set_target(target);
  for (int n = 0; n < 600; ++n) cycle();
  ASSERT_EQ(runtime_->state(), RuntimeState::run) << to_string(runtime_->active_fault());
  ASSERT_TRUE(runtime_->has_setpoints());
  EXPECT_EQ(runtime_->last_ik_report().outcome, protocol::IkOutcome::converged);
  const Cables lengths = drive_lengths();
  for (int i = 0; i < cables_; ++i)
    EXPECT_NEAR(double(lengths[i]), double(runtime_->setpoints_mm()[i]), 0.002) << "cable " << i;
  const auto reached = runtime_->latest_pose().pose.position_mm;
  EXPECT_NEAR(double(reached.x()), target.position_mm[0], 0.05);
  EXPECT_NEAR(double(reached.y()), target.position_mm[1], 0.05);
}

TEST_F(RuntimeCia402Test, DriveEmergencyIsAFaultNamingItsNodeUntilRecovered) {
  make_runtime();
  ASSERT_GT(start_drives(), 0);
  const int cable = cables_ / 2 + 2;  // on the second bus, node 3
  drives_[cable].fault(drive_bus_[1].node(1), 0x2310);
  ASSERT_GT(cycles_until(RuntimeState::fault, 3), 0);
  EXPECT_EQ(runtime_->active_fault(), FaultCode::drive_fault);
  EXPECT_EQ(runtime_->active_fault_detail(), FaultDetail::drive(3));
  EXPECT_EQ(runtime_->drives_health().cable, cable);
  EXPECT_EQ(runtime_->drives_health().detail, 0x2310u);
  const std::string line = "fault: emergency, drive 3 (cable " + std::to_string(cable) + "), detail 8976";
  EXPECT_NE(std::find(platform_->console.lines.begin(), platform_->console.lines.end(), line),
            platform_->console.lines.end())
      << line;
  // It stays in FAULT while the positions still come, and a malformed
  // command does not recover it.
  for (int n = 0; n < 50; ++n) cycle();
  EXPECT_EQ(runtime_->state(), RuntimeState::fault);
  hal::CanFrame command;
  protocol::encode(protocol::DrivesCommand{}, command);
  command.data[0] = 2;
  platform_->host_node.send(command);
  for (int n = 0; n < 50; ++n) cycle();
  EXPECT_EQ(runtime_->state(), RuntimeState::fault);
  // The host's DRIVES_COMMAND recovers them.
  command.data[0] = 1;
  platform_->host_node.send(command);
  ASSERT_GT(start_drives(2000), 0) << to_string(runtime_->active_fault());
  EXPECT_EQ(drives_[cable].statusword, 0x0237);
}

TEST_F(RuntimeCia402Test, HeartbeatLossAndRefusedConfiguration) {
  make_runtime();
  ASSERT_GT(start_drives(), 0);
  drives_[1].heartbeat_on = false;
  ASSERT_GT(cycles_until(RuntimeState::fault, 100), 0);
  EXPECT_EQ(runtime_->active_fault(), FaultCode::drive_silent);
  EXPECT_EQ(runtime_->active_fault_detail(), FaultDetail::drive(2));

  // A drive that refuses CSP: the runtime never runs.
  for (auto& drive : drives_) {
    const NodeId node = drive.node;
    drive = TestDrive{};
    drive.node = node;
  }
  drives_[0].refused.insert(0x6060);
  make_runtime();
  for (int n = 0; n < 300; ++n) cycle();
  EXPECT_EQ(runtime_->state(), RuntimeState::fault);
  EXPECT_EQ(runtime_->active_fault(), FaultCode::drive_refused);
  EXPECT_EQ(runtime_->active_fault_detail(), FaultDetail::drive(1));
}

// A drive that never answers at boot; one whose TPDOs come twice (taken
// once, no fault); one whose TPDOs stop (stale after stale_cycles): each
// in STATUS with its node id.
TEST_F(RuntimeCia402Test, SilentAtBootRepeatedAndMissingPositions) {
  drives_[3].powered = false;
  make_runtime();
  int cycles = 0;
  while (runtime_->active_fault() != FaultCode::drive_silent && ++cycles < 3000) cycle();
  EXPECT_EQ(runtime_->state(), RuntimeState::fault);
  EXPECT_EQ(runtime_->active_fault(), FaultCode::drive_silent);
  EXPECT_EQ(runtime_->active_fault_detail(), FaultDetail::drive(config_.drives[3].node));
  // Not before the boot timeout (2 s of 1 ms cycles).
  EXPECT_GE(cycles, int(config_.boot_timeout_ms));

  drives_[3].powered = true;
  drives_[2].repeat_tpdo = true;
  ASSERT_TRUE(runtime_->recover_drives());
  ASSERT_GT(start_drives(3000), 0) << to_string(runtime_->active_fault());
  for (int n = 0; n < 200; ++n) cycle();
  EXPECT_EQ(runtime_->state(), RuntimeState::run) << to_string(runtime_->active_fault());
  EXPECT_NEAR((runtime_->latest_pose().pose.position_mm -
               [&] {
                 PoseEstimate e;
                 EXPECT_EQ(runtime_->estimate_pose(drive_lengths(), e), model::Status::ok);
                 return e.pose.position_mm;
               }())
                  .norm(),
              0.0, 1e-3);

  drives_[5].answers_sync = false;
  cycles = 0;
  while (runtime_->state() != RuntimeState::fault && ++cycles < 100) cycle();
  EXPECT_EQ(runtime_->active_fault(), FaultCode::drive_silent);
  EXPECT_EQ(runtime_->active_fault_detail(), FaultDetail::drive(config_.drives[5].node));
  EXPECT_GE(cycles, int(config_.stale_cycles));
}

TEST_F(RuntimeCia402Test, CableFeedbackFramesIgnored) {
  make_runtime();
  ASSERT_GT(start_drives(), 0);
  for (int n = 0; n < 5; ++n) cycle();
  const auto before = runtime_->latest_pose().pose.position_mm;
  // A protocol drive's CABLE_FEEDBACK on the host's bus, 5 mm off.
  const Cables lengths = drive_lengths();
  protocol::CableFeedback feedback;
  feedback.segment = 0;
  for (int k = 0; k < 4; ++k) feedback.lengths_mm[k] = double(lengths[k]) + 5.0;
  hal::CanFrame frame;
  ASSERT_TRUE(protocol::encode(feedback, frame));
  ASSERT_EQ(platform_->host_node.send(frame), hal::CanStatus::ok);
  cycle();
  EXPECT_NEAR((runtime_->latest_pose().pose.position_mm - before).norm(), 0.0, 1e-4);
}

}  // namespace
}  // namespace cdcr::firmware::canopen
