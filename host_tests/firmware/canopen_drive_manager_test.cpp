// The CiA 402 drive manager against drives written here to CiA 301 and
// 402-2 as a device would follow them (NMT, expedited SDO server, PDOs on
// SYNC, heartbeat, EMCY, the power state machine), on the simulated bus:
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

namespace cdcr::firmware::canopen {
namespace {

struct TestDrive {
  NodeId node = 0;
  NmtState nmt = NmtState::boot_up;
  bool powered = true;          // answers at all
  bool heartbeat_on = true;     // produces its heartbeat
  bool answers_sync = true;     // sends its TPDO on SYNC
  bool repeat_tpdo = false;     // sends each TPDO twice
  std::set<std::uint16_t> refused;  // objects whose writes it aborts (value range)
  std::map<std::uint32_t, std::uint32_t> objects;  // (index << 8 | subindex) -> value
  std::vector<std::uint32_t> written;             // in order
  std::uint16_t statusword = 0x0250;              // switch on disabled
  std::uint16_t controlword = 0;
  std::uint16_t pending_controlword = 0;
  std::int32_t pending_target = 0;
  bool has_pending = false;
  double position = 0;
  std::int32_t target = 0;
  std::uint32_t ms = 0;

  std::uint16_t heartbeat_ms() const {
    auto it = objects.find(0x101700);
    return it == objects.end() ? 0 : std::uint16_t(it->second);
  }
  void step_power_state(std::uint16_t cw) {
    const bool fault_reset = (cw & 0x80) && !(controlword & 0x80);
    controlword = cw;
    switch (statusword) {
      case 0x0218:  // fault
        if (fault_reset) statusword = 0x0250;
        return;
      case 0x0250:
        if ((cw & 0x87) == 0x06) statusword = 0x0231;
        return;
      case 0x0231:
        if ((cw & 0x8F) == 0x07) statusword = 0x0233;
        if ((cw & 0x8F) == 0x0F) statusword = 0x0237;
        if ((cw & 0x02) == 0) statusword = 0x0250;
        return;
      case 0x0233:
        if ((cw & 0x8F) == 0x0F) statusword = 0x0237;
        if ((cw & 0x8F) == 0x06) statusword = 0x0231;
        if ((cw & 0x02) == 0) statusword = 0x0250;
        return;
      case 0x0237:
        if ((cw & 0x86) == 0x02) statusword = 0x0217;  // quick stop
        else if ((cw & 0x8F) == 0x07) statusword = 0x0233;
        else if ((cw & 0x8F) == 0x06) statusword = 0x0231;
        else if ((cw & 0x02) == 0) statusword = 0x0250;
        return;
      case 0x0217:
        if ((cw & 0x02) == 0) statusword = 0x0250;
        return;
    }
  }
  void fault(hal::CanBus& bus, std::uint16_t error_code) {
    statusword = 0x0218;
    Emergency emergency;
    emergency.node = node;
    emergency.error_code = error_code;
    emergency.error_register = 0x03;
    bus.send(emergency_frame(emergency));
  }

  void take(const hal::CanFrame& frame, hal::CanBus& bus) {
    if (!powered) return;
    if (frame.id == kNmtId && frame.dlc == 2 && (frame.data[1] == 0 || frame.data[1] == node)) {
      switch (frame.data[0]) {
        case 0x82:
        case 0x81:
          objects.erase(0x101700);
          nmt = NmtState::pre_operational;
          bus.send(heartbeat_frame({node, NmtState::boot_up}));
          break;
        case 0x01: nmt = NmtState::operational; break;
        case 0x02: nmt = NmtState::stopped; break;
        case 0x80: nmt = NmtState::pre_operational; break;
      }
      return;
    }
    if (frame.id == kSdoClientBase + node && nmt != NmtState::stopped) {
      const std::uint16_t index = std::uint16_t(frame.data[1] | (frame.data[2] << 8));
      const std::uint8_t sub = frame.data[3];
      hal::CanFrame reply;
      reply.id = kSdoServerBase + node;
      reply.dlc = 8;
      reply.data[1] = frame.data[1];
      reply.data[2] = frame.data[2];
      reply.data[3] = sub;
      if ((frame.data[0] & 0xE3) == 0x23 && !refused.count(index)) {
        const int size = 4 - ((frame.data[0] >> 2) & 3);
        std::uint32_t value = 0;
        for (int i = 0; i < size; ++i) value |= std::uint32_t(frame.data[4 + i]) << (8 * i);
        objects[(std::uint32_t(index) << 8) | sub] = value;
        written.push_back((std::uint32_t(index) << 8) | sub);
        reply.data[0] = 0x60;
      } else {
        reply.data[0] = 0x80;
        const std::uint32_t code = sdo::kAbortValueRange;
        for (int i = 0; i < 4; ++i) reply.data[4 + i] = std::uint8_t(code >> (8 * i));
      }
      bus.send(reply);
      return;
    }
    if (nmt != NmtState::operational) return;
    DriveCommand command;
    if (decode_rpdo(frame, command) && command.node == node) {
      pending_controlword = command.controlword;
      pending_target = command.target_position;
      has_pending = true;
      return;
    }
    if (frame.id == kSyncId && frame.dlc == 0) {
      if (has_pending) {
        step_power_state(pending_controlword);
        if (statusword == 0x0237) target = pending_target;
        has_pending = false;
      }
      // A first-order position loop: half the way each cycle.
      if (statusword == 0x0237) position += 0.5 * (double(target) - position);
      if (!answers_sync) return;
      const hal::CanFrame tpdo = tpdo_frame({node, statusword, std::int32_t(position)});
      bus.send(tpdo);
      if (repeat_tpdo) bus.send(tpdo);
    }
  }
  // One millisecond of the drive's own time.
  void tick(hal::CanBus& bus) {
    ++ms;
    const std::uint16_t period = heartbeat_ms();
    if (powered && heartbeat_on && period > 0 && ms % period == 0) bus.send(heartbeat_frame({node, nmt}));
  }
};

class DriveManagerTest : public ::testing::Test {
 protected:
  static constexpr int kDrives = 16;

  void SetUp() override {
    config_.drive_count = kDrives;
    for (int i = 0; i < kDrives; ++i) {
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
    manager.run_cycle(bus_.node(0));
    hal::CanFrame frame;
    while (bus_.node(1).receive(frame) == hal::CanStatus::ok)
      for (auto& drive : drives_) drive.take(frame, bus_.node(1));
    for (auto& drive : drives_) drive.tick(bus_.node(1));
  }
  // The cycle's start: what the drives sent since the last SYNC.
  void take_frames(DriveManager& manager) {
    hal::CanFrame frame;
    while (bus_.node(0).receive(frame) == hal::CanStatus::ok) manager.take(frame);
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
  manager.run_cycle(bus_.node(0));  // A+1, its frames taken above
  hal::CanFrame frame;
  while (bus_.node(1).receive(frame) == hal::CanStatus::ok)
    for (auto& drive : drives_) drive.take(frame, bus_.node(1));
  const int cycles = run_until(manager, DrivePhase::fault, 50);
  EXPECT_EQ(manager.fault().fault, DriveFault::input_stale);
  EXPECT_EQ(manager.fault().node, 7);
  EXPECT_EQ(cycles, 9);
}

TEST(DriveManagerConfig, Refusals) {
  DriveManagerConfig config;
  EXPECT_EQ(validate(config), DriveConfigStatus::no_drives);
  config.drive_count = 2;
  config.drives[0] = {1, 1000.0, 0.0};
  config.drives[1] = {1, 1000.0, 0.0};
  EXPECT_EQ(validate(config), DriveConfigStatus::node_repeated);
  config.drives[1] = {128, 1000.0, 0.0};
  EXPECT_EQ(validate(config), DriveConfigStatus::node_invalid);
  config.drives[1] = {2, 0.0, 0.0};
  EXPECT_EQ(validate(config), DriveConfigStatus::scale_invalid);
  config.drives[1] = {2, -500.0, 0.0};
  EXPECT_EQ(validate(config), DriveConfigStatus::ok);
  config.timing.sync_window_us = 2000;
  EXPECT_EQ(validate(config), DriveConfigStatus::timing_invalid);
  DriveManager manager(config);
  EXPECT_EQ(manager.phase(), DrivePhase::fault);
  EXPECT_EQ(manager.fault().fault, DriveFault::config_invalid);
}

}  // namespace
}  // namespace cdcr::firmware::canopen
