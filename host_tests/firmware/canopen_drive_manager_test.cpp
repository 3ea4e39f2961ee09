// The CiA 402 drive manager against drives written to CiA 301 and 402-2 as
// a device would follow them (cia402_test_drive.hpp), on the simulated bus:
// boot to Operation enabled, the setpoints reached within the speed limit,
// and each fault the manager must name. The drives on the npm `canopen`
// stack (host_tests/canopen) check the same against a stack this project did
// not write.

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/firmware/canopen/drive_manager.hpp>
#include <cdcr/sim/virtual_can.hpp>

#include "cia402_test_drive.hpp"

namespace cdcr::firmware::canopen {
namespace {

class DriveManagerTest : public ::testing::Test {
 protected:
  static constexpr int kDrives = 16;

  void SetUp() override {
    config_.drive_count = kDrives;
    for (int i = 0; i < kDrives; ++i) {
      config_.drives[i].bus = 0;
    config_.drives[i].node = NodeId(i + 1);
      config_.drives[i].counts_per_mm = (i % 2) ? -1000.0 : 1000.0;  // every other drive wound the other way
      config_.drives[i].offset_mm = 100.0;
      drives_[i].node = NodeId(i + 1);
      drives_[i].position = 0;
    }
    config_.timing = {1000, 400, 20};
  }

  // One 1 ms cycle: the manager takes its frames and sends; the drives
  // answer; their own time advances.
  void cycle(DriveManager& manager) {
    take_frames(manager);
    manager.run_cycle(buses_);
    hal::CanFrame frame;
    while (bus_.node(1).receive(frame) == hal::CanStatus::ok)
      for (auto& drive : drives_) drive.take(frame, bus_.node(1));
    for (auto& drive : drives_) drive.tick(bus_.node(1));
  }
  // The cycle's start: what the drives sent since the last SYNC.
  void take_frames(DriveManager& manager) {
    hal::CanFrame frame;
    while (bus_.node(0).receive(frame) == hal::CanStatus::ok) manager.take(frame, 0);
  }
  int run_until(DriveManager& manager, DrivePhase phase, int limit) {
    for (int n = 1; n <= limit; ++n) {
      cycle(manager);
      if (manager.phase() == phase) return n;
    }
    return -1;
  }

  DriveManagerConfig config_;
  sim::VirtualCanBus bus_;
  hal::CanBus* const buses_[kMaxDriveBuses] = {&bus_.node(0), nullptr, nullptr, nullptr};
  TestDrive drives_[kDrives];
};

TEST_F(DriveManagerTest, BootsConfiguresAndEnablesSixteenDrives) {
  DriveManager manager(config_);
  const int cycles = run_until(manager, DrivePhase::operational, 1000);
  ASSERT_GT(cycles, 0) << to_string(manager.phase()) << ": " << to_string(manager.fault().fault) << " node "
                       << int(manager.fault().node);
  // 18 writes a drive, 4 requests a cycle over 16 drives, answered in the same cycle.
  EXPECT_LE(cycles, 16 * 18 / 4 + 10);
  for (const auto& drive : drives_) {
    ASSERT_EQ(drive.written.size(), cia402::kConfigurationWrites);
    EXPECT_EQ(drive.objects.at(0x606000), 8u) << "cyclic synchronous position";
    EXPECT_EQ(drive.objects.at(0x101700), 20u);
    EXPECT_EQ(drive.objects.at(0x100700), 400u);
    EXPECT_EQ(drive.objects.at(0x180001), 0x180u + drive.node) << "TPDO valid on 0x180 + node";
    EXPECT_EQ(drive.objects.at(0x160002), 0x607A0020u);
    EXPECT_EQ(drive.statusword, 0x0237);
    EXPECT_EQ(drive.nmt, NmtState::operational);
  }
  // The positions at enable: 0 counts = the offset.
  take_frames(manager);
  ASSERT_TRUE(manager.positions_fresh());
  EXPECT_DOUBLE_EQ(manager.length_mm(0), 100.0);
}

TEST_F(DriveManagerTest, SetpointsReachedWithinTheSpeedLimit) {
  config_.max_speed_mm_per_s = 10.0;  // 0.01 mm = 10 counts a cycle
  DriveManager manager(config_);
  ASSERT_GT(run_until(manager, DrivePhase::operational, 1000), 0);
  double setpoints[kDrives];
  for (int i = 0; i < kDrives; ++i) setpoints[i] = 100.0 + 0.5 * (i - 8);  // up to 4 mm away
  ASSERT_TRUE(manager.set_setpoints(setpoints, kDrives));
  std::int32_t previous[kDrives];
  for (int i = 0; i < kDrives; ++i) previous[i] = manager.target_counts(i);
  for (int n = 0; n < 500; ++n) {
    cycle(manager);
    ASSERT_EQ(manager.phase(), DrivePhase::operational);
    for (int i = 0; i < kDrives; ++i) {
      EXPECT_LE(std::abs(manager.target_counts(i) - previous[i]), 10) << "drive " << i << " cycle " << n;
      previous[i] = manager.target_counts(i);
    }
  }
  for (int i = 0; i < kDrives; ++i) {
    EXPECT_NEAR(manager.length_mm(i), setpoints[i], 0.002) << "drive " << i;
    // The direction: drive 1 counts down for a longer cable.
    EXPECT_EQ(manager.target_counts(i), std::int32_t(std::lround((setpoints[i] - 100.0) * config_.drives[i].counts_per_mm)));
  }
  const double beyond[kDrives] = {1e9};
  EXPECT_FALSE(manager.set_setpoints(beyond, kDrives));
  EXPECT_EQ(manager.fault().fault, DriveFault::setpoint_range);
}

TEST_F(DriveManagerTest, RefusedConfigurationWriteNamesDriveAndObject) {
  drives_[2].refused.insert(0x6060);
  DriveManager manager(config_);
  ASSERT_GT(run_until(manager, DrivePhase::fault, 1000), 0);
  EXPECT_EQ(manager.fault().fault, DriveFault::sdo_aborted);
  EXPECT_EQ(manager.fault().node, 3);
  EXPECT_EQ(manager.fault().detail, sdo::kAbortValueRange);
  EXPECT_EQ(manager.fault().object.index, 0x6060);
}

TEST_F(DriveManagerTest, DriveSilentAtBootNamedAfterTheTimeout) {
  drives_[7].powered = false;
  DriveManager manager(config_);
  const int cycles = run_until(manager, DrivePhase::fault, 5000);
  EXPECT_EQ(manager.fault().fault, DriveFault::boot_silent);
  EXPECT_EQ(manager.fault().node, 8);
  EXPECT_GE(cycles, 2000);
  EXPECT_LE(cycles, 2003);
}

TEST_F(DriveManagerTest, HeartbeatLoss) {
  DriveManager manager(config_);
  ASSERT_GT(run_until(manager, DrivePhase::operational, 1000), 0);
  for (int n = 0; n < 200; ++n) cycle(manager);
  ASSERT_EQ(manager.phase(), DrivePhase::operational);
  drives_[11].heartbeat_on = false;
  const int cycles = run_until(manager, DrivePhase::fault, 200);
  EXPECT_EQ(manager.fault().fault, DriveFault::heartbeat_lost);
  EXPECT_EQ(manager.fault().node, 12);
  // Three 20 ms periods, from its last heartbeat.
  EXPECT_GT(cycles, 40);
  EXPECT_LE(cycles, 62);
}

TEST_F(DriveManagerTest, EmergencyThenRecovery) {
  DriveManager manager(config_);
  ASSERT_GT(run_until(manager, DrivePhase::operational, 1000), 0);
  drives_[4].fault(bus_.node(1), 0x2310);
  cycle(manager);
  ASSERT_EQ(manager.phase(), DrivePhase::fault);
  EXPECT_EQ(manager.fault().fault, DriveFault::emergency);
  EXPECT_EQ(manager.fault().node, 5);
  EXPECT_EQ(manager.fault().detail, 0x2310u);
  // In fault the others are quick-stopped and the positions still come.
  for (int n = 0; n < 5; ++n) cycle(manager);
  EXPECT_EQ(drives_[0].statusword, 0x0217);
  take_frames(manager);
  EXPECT_TRUE(manager.positions_fresh());
  manager.recover();
  ASSERT_GT(run_until(manager, DrivePhase::operational, 2000), 0)
      << to_string(manager.fault().fault) << " node " << int(manager.fault().node);
  for (const auto& drive : drives_) EXPECT_EQ(drive.statusword, 0x0237);
}

// A heartbeat sent just before the NMT start reached the drive arrives after
// it: pre-operational once more, not a fault. After an operational one, or
// once enabled, it is.
TEST_F(DriveManagerTest, PreOperationalHeartbeatInFlightAtTheStart) {
  DriveManager manager(config_);
  ASSERT_GT(run_until(manager, DrivePhase::enable, 1000), 0);
  bus_.node(1).send(heartbeat_frame({3, NmtState::pre_operational}));
  cycle(manager);
  ASSERT_NE(manager.phase(), DrivePhase::fault) << to_string(manager.fault().fault);
  ASSERT_GT(run_until(manager, DrivePhase::operational, 1000), 0);
  bus_.node(1).send(heartbeat_frame({3, NmtState::pre_operational}));
  cycle(manager);
  EXPECT_EQ(manager.fault().fault, DriveFault::nmt_left);
  EXPECT_EQ(manager.fault().node, 3);
  EXPECT_EQ(manager.fault().detail, 0x7Fu);
}

TEST_F(DriveManagerTest, StatuswordFaultWithoutEmergency) {
  DriveManager manager(config_);
  ASSERT_GT(run_until(manager, DrivePhase::operational, 1000), 0);
  drives_[9].statusword = 0x0218;
  run_until(manager, DrivePhase::fault, 5);
  EXPECT_EQ(manager.fault().fault, DriveFault::drive_fault);
  EXPECT_EQ(manager.fault().node, 10);
  EXPECT_EQ(manager.fault().detail, 0x0218u);
}

TEST_F(DriveManagerTest, DriveLeavingOperationEnabled) {
  DriveManager manager(config_);
  ASSERT_GT(run_until(manager, DrivePhase::operational, 1000), 0);
  drives_[0].statusword = 0x0250;  // switch on disabled (a drive's own disable input)
  run_until(manager, DrivePhase::fault, 5);
  EXPECT_EQ(manager.fault().fault, DriveFault::left_operation);
  EXPECT_EQ(manager.fault().node, 1);
}

TEST_F(DriveManagerTest, RepeatedTpdoCountedLateTpdoStale) {
  DriveManager manager(config_);
  ASSERT_GT(run_until(manager, DrivePhase::operational, 1000), 0);
  drives_[3].repeat_tpdo = true;
  for (int n = 0; n < 20; ++n) cycle(manager);
  EXPECT_EQ(manager.phase(), DrivePhase::operational);
  EXPECT_GE(manager.repeated_pdos(), 19u);
  drives_[3].repeat_tpdo = false;
  drives_[6].answers_sync = false;
  // Cycle A sends the first SYNC it leaves unanswered; cycles A+1 to A+10
  // take no position of it, and the tenth is the fault.
  cycle(manager);  // A
  take_frames(manager);
  EXPECT_FALSE(manager.positions_fresh());
  manager.run_cycle(buses_);  // A+1, its frames taken above
  hal::CanFrame frame;
  while (bus_.node(1).receive(frame) == hal::CanStatus::ok)
    for (auto& drive : drives_) drive.take(frame, bus_.node(1));
  const int cycles = run_until(manager, DrivePhase::fault, 50);
  EXPECT_EQ(manager.fault().fault, DriveFault::input_stale);
  EXPECT_EQ(manager.fault().node, 7);
  EXPECT_EQ(cycles, 9);
}

// Four drives on each of two buses, node ids 1 to 4 on both: each bus gets
// its own NMT, SDO, RPDOs and SYNC, and a frame counts for the drive of the
// bus it came on.
TEST(DriveManagerBuses, NodeIdsRepeatAcrossBuses) {
  sim::VirtualCanBus first, second;
  hal::CanBus* const buses[kMaxDriveBuses] = {&first.node(0), &second.node(0), nullptr, nullptr};
  DriveManagerConfig config;
  config.drive_count = 8;
  config.bus_count = 2;
  TestDrive drives[8];
  for (int i = 0; i < 8; ++i) {
    config.drives[i] = {std::uint8_t(i / 4), NodeId(i % 4 + 1), 1000.0, 50.0};
    drives[i].node = NodeId(i % 4 + 1);
    drives[i].position = 1000.0 * i;
  }
  ASSERT_EQ(validate(config), DriveConfigStatus::ok);
  DriveManager manager(config);
  sim::VirtualCanBus* bus_of[2] = {&first, &second};
  for (int n = 0; n < 300 && manager.phase() != DrivePhase::operational; ++n) {
    hal::CanFrame frame;
    for (int b = 0; b < 2; ++b)
      while (bus_of[b]->node(0).receive(frame) == hal::CanStatus::ok) manager.take(frame, b);
    manager.run_cycle(buses);
    for (int b = 0; b < 2; ++b) {
      while (bus_of[b]->node(1).receive(frame) == hal::CanStatus::ok)
        for (int i = 4 * b; i < 4 * b + 4; ++i) drives[i].take(frame, bus_of[b]->node(1));
      for (int i = 4 * b; i < 4 * b + 4; ++i) drives[i].tick(bus_of[b]->node(1));
    }
  }
  ASSERT_EQ(manager.phase(), DrivePhase::operational) << to_string(manager.fault().fault);
  hal::CanFrame frame;
  for (int b = 0; b < 2; ++b)
    while (bus_of[b]->node(0).receive(frame) == hal::CanStatus::ok) manager.take(frame, b);
  ASSERT_TRUE(manager.positions_fresh());
  for (int i = 0; i < 8; ++i) EXPECT_DOUBLE_EQ(manager.length_mm(i), 50.0 + i) << "cable " << i;
  config.drives[5].node = 1;  // two node 1 on the second bus
  EXPECT_EQ(validate(config), DriveConfigStatus::node_repeated);
  config.drives[5].bus = 2;
  EXPECT_EQ(validate(config), DriveConfigStatus::bus_invalid);
}

TEST(DriveManagerConfig, Refusals) {
  DriveManagerConfig config;
  EXPECT_EQ(validate(config), DriveConfigStatus::no_drives);
  config.drive_count = 2;
  config.drives[0] = {0, 1, 1000.0, 0.0};
  config.drives[1] = {0, 1, 1000.0, 0.0};
  EXPECT_EQ(validate(config), DriveConfigStatus::node_repeated);
  config.drives[1] = {0, 128, 1000.0, 0.0};
  EXPECT_EQ(validate(config), DriveConfigStatus::node_invalid);
  config.drives[1] = {0, 2, 0.0, 0.0};
  EXPECT_EQ(validate(config), DriveConfigStatus::scale_invalid);
  config.drives[1] = {0, 2, -500.0, 0.0};
  EXPECT_EQ(validate(config), DriveConfigStatus::ok);
  config.timing.sync_window_us = 2000;
  EXPECT_EQ(validate(config), DriveConfigStatus::timing_invalid);
  DriveManager manager(config);
  EXPECT_EQ(manager.phase(), DrivePhase::fault);
  EXPECT_EQ(manager.fault().fault, DriveFault::config_invalid);
}

}  // namespace
}  // namespace cdcr::firmware::canopen
