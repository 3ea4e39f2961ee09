// The bus budget (firmware/protocol/bus_budget.hpp) against frames counted by
// hand. A classical data frame of d bytes with an 11-bit identifier has
// n = 34 + 8d bits from SOF to the end of its CRC, at most (n - 1) / 4 stuff
// bits among them, and 13 after (CRC delimiter, ACK, EOF, intermission):
//   d = 8: 98 + 24 + 13 = 135 bits;  d = 7: 90 + 22 + 13 = 125;
//   d = 6: 82 + 20 + 13 = 115.
#include <string>

#include <gtest/gtest.h>

#include "cdcr/firmware/canopen/bus_budget.hpp"
#include "cdcr/firmware/protocol/bus_budget.hpp"

namespace cdcr::firmware::protocol {
namespace {

const MessageLoad* line_of(const BusBudget& budget, const std::string& name) {
  for (int i = 0; i < budget.message_count; ++i) {
    if (name == budget.messages[i].name) return &budget.messages[i];
  }
  return nullptr;
}

constexpr BusSetup kClassical1Mbit{hal::CanFormat::classical, {1000000, 0}};

// CiA 402 drives: a SYNC (d = 0: 34 + 8 + 13 = 55 bits), an RPDO1 and a
// TPDO1 of 6 bytes (115) per drive every cycle, a heartbeat (d = 1:
// 42 + 10 + 13 = 65) per drive every heartbeat period.
TEST(BusBudget, Cia402DrivesOnABus) {
  const BusBudget four = canopen::cia402_bus_budget(4, 1000, 50, kClassical1Mbit);
  EXPECT_NEAR(four.load, (1000 * 55.0 + 8000 * 115.0 + 80 * 65.0) / 1e6, 1e-12);  // 98.0 %
  EXPECT_FALSE(four.fits());
  EXPECT_EQ(line_of(four, "SYNC")->worst_bits, 55u);
  EXPECT_EQ(line_of(four, "RPDO1")->worst_bits, 115u);
  EXPECT_EQ(line_of(four, "HEARTBEAT")->worst_bits, 65u);
  EXPECT_NEAR(line_of(four, "HEARTBEAT")->frames_per_s, 80.0, 1e-12);
  // At 500 Hz the four fit (49.3 %): 16 drives, four to a bus on four buses.
  const BusBudget slower = canopen::cia402_bus_budget(4, 500, 50, kClassical1Mbit);
  EXPECT_NEAR(slower.load, (500 * 55.0 + 4000 * 115.0 + 80 * 65.0) / 1e6, 1e-12);
  EXPECT_TRUE(slower.fits());
  // Two drives a bus fit at 1 kHz (51.8 %): 16 need eight buses.
  EXPECT_TRUE(canopen::cia402_bus_budget(2, 1000, 50, kClassical1Mbit).fits());
  EXPECT_FALSE(canopen::cia402_bus_budget(3, 1000, 50, kClassical1Mbit).fits());
}

TEST(BusBudget, ThePapersRobotEstimatingAt1kHz) {
  BusTraffic traffic;  // 4 segments, 1 kHz, a pose every cycle, STATUS/STATS every 10
  traffic.rates.uncertainty_every = 5;
  const BusBudget budget = bus_budget(traffic, kClassical1Mbit);
  // A second: 4,000 CABLE_FEEDBACK (8 bytes), 1,000 each of POSE_POSITION_XY
  // (8), POSE_POSITION_Z (6) and POSE_ORIENTATION (8), 200 POSE_UNCERTAINTY
  // (7), 100 each of STATUS and STATS (8).
  const double bits = 4000 * 135.0 + 1000 * 135.0 + 1000 * 115.0 + 1000 * 135.0 + 200 * 125.0 + 200 * 135.0;
  EXPECT_NEAR(budget.load, bits / 1e6, 1e-12);
  EXPECT_NEAR(budget.frames_per_s, 7400.0, 1e-9);
  EXPECT_FALSE(budget.fits());  // 0.977: most of the bus at the worst case
  ASSERT_NE(line_of(budget, "CABLE_FEEDBACK"), nullptr);
  EXPECT_EQ(line_of(budget, "CABLE_FEEDBACK")->worst_bits, 135u);
  EXPECT_EQ(line_of(budget, "POSE_POSITION_Z")->worst_bits, 115u);
  EXPECT_EQ(line_of(budget, "POSE_UNCERTAINTY")->worst_bits, 125u);
  EXPECT_EQ(line_of(budget, "CABLE_SETPOINT"), nullptr);  // nothing streamed
  // Without stuffing: 111, 95 (d = 6) and 103 (d = 7) bits.
  const double unstuffed = 4000 * 111.0 + 2000 * 111.0 + 1000 * 95.0 + 200 * 103.0 + 200 * 111.0;
  EXPECT_NEAR(budget.unstuffed_load, unstuffed / 1e6, 1e-12);
}

TEST(BusBudget, StreamingAddsTargetsSetpointsAndAReportPerTarget) {
  BusTraffic traffic;
  traffic.streaming = true;
  traffic.rates.uncertainty_every = 5;
  BusTraffic estimating_only = traffic;
  estimating_only.streaming = false;
  const BusBudget estimating = bus_budget(estimating_only, kClassical1Mbit);
  const BusBudget budget = bus_budget(traffic, kClassical1Mbit);
  // 4,000 CABLE_SETPOINT, 1,000 each of TARGET_ORIENTATION, _POSITION_XY
  // (8 bytes) and _POSITION_Z (6), 1,100 IK_REPORT (8).
  const double more = 4000 * 135.0 + 2000 * 135.0 + 1000 * 115.0 + 1100 * 135.0;
  EXPECT_NEAR(budget.load - estimating.load, more / 1e6, 1e-12);
  EXPECT_GT(budget.load, 1.8);
  EXPECT_EQ(line_of(budget, "IK_REPORT")->frames_per_s, 1100.0);
}

TEST(BusBudget, RatesAndBitRatesScaleIt) {
  BusTraffic traffic;
  traffic.rates.uncertainty_every = 5;
  const BusBudget base = bus_budget(traffic, kClassical1Mbit);
  traffic.rates.pose_every = 4;
  const BusBudget fewer_poses = bus_budget(traffic, kClassical1Mbit);
  EXPECT_NEAR(base.load - fewer_poses.load, 0.75 * 1000 * (135.0 + 115.0 + 135.0) / 1e6, 1e-12);
  const BusBudget half_rate = bus_budget(traffic, BusSetup{hal::CanFormat::classical, {500000, 0}});
  EXPECT_NEAR(half_rate.load, 2.0 * fewer_poses.load, 1e-12);
  traffic.cycle_hz = 500;
  EXPECT_NEAR(bus_budget(traffic, kClassical1Mbit).load, 0.5 * fewer_poses.load, 1e-12);
  traffic.segments = 2;
  // 500 Hz, 2 segments, a pose every 4 cycles, radii every 5, STATUS/STATS every 10.
  const double bits = 1000 * 135.0 + 125 * (135.0 + 115.0 + 135.0) + 100 * 125.0 + 50 * 135.0 * 2;
  EXPECT_NEAR(bus_budget(traffic, kClassical1Mbit).load, bits / 1e6, 1e-12);
}

// A CAN FD frame with the bit-rate switch, 11-bit identifier, d data bytes:
// at the nominal rate SOF, identifier, RRS, IDE, FDF, res, BRS (17 bits)
// with at most 4 stuff bits, then CRC delimiter, ACK, EOF and intermission
// (13): 34 bits. At the data rate ESI and DLC (5), 8d data bits, at most
// (21 + 8d) / 4 - 4 dynamic stuff bits, and the CRC field: stuff count (4),
// CRC (17 up to 16 bytes, 21 above), its fixed stuff bits (one per 4 bits)
// and delimiter: 27 or 32 bits. At 1 Mbit/s and 5 Mbit/s:
//   d = 8:  34 + (5 + 64 + 17 + 27) = 34 + 113:  34 + 22.6 = 56.6 us;
//   d = 24: 34 + (5 + 192 + 49 + 32) = 34 + 278: 34 + 55.6 = 89.6 us;
//   d = 32: 34 + (5 + 256 + 65 + 32) = 34 + 358: 34 + 71.6 = 105.6 us.
constexpr BusSetup kFd1And5Mbit{hal::CanFormat::fd_bit_rate_switch, {1000000, 5000000}};

TEST(BusBudget, ThePapersRobotStreamingOnOneFdBus) {
  BusTraffic traffic;
  traffic.streaming = true;
  const BusBudget budget = bus_budget(traffic, kFd1And5Mbit);
  // A second: 4,000 CABLE_FEEDBACK and 1,100 IK_REPORT, 100 each of STATUS
  // and STATS (8 bytes); one CABLE_SETPOINTS_FD for the 4 segments and one
  // POSE_FD (32 bytes) and one TARGET_FD (24) every cycle.
  const double us = (4000 + 1100 + 200) * 56.6 + 2000 * 105.6 + 1000 * 89.6;
  EXPECT_NEAR(budget.load, us / 1e6, 1e-9);
  EXPECT_TRUE(budget.fits());  // 0.601
  EXPECT_EQ(line_of(budget, "POSE_FD")->worst_bits, 34u + 358u);
  EXPECT_EQ(line_of(budget, "TARGET_FD")->worst_bits, 34u + 278u);
  EXPECT_EQ(line_of(budget, "CABLE_SETPOINTS_FD")->frames_per_s, 1000.0);
  for (const char* classical : {"POSE_POSITION_XY", "POSE_UNCERTAINTY", "TARGET_POSITION_Z", "CABLE_SETPOINT"}) {
    EXPECT_EQ(line_of(budget, classical), nullptr) << classical;
  }
  traffic.segments = 5;  // a second setpoint frame
  EXPECT_EQ(line_of(bus_budget(traffic, kFd1And5Mbit), "CABLE_SETPOINTS_FD")->frames_per_s, 2000.0);
}

TEST(BusBudget, TwoBusesShareTheTrafficOut) {
  BusTraffic traffic;
  traffic.streaming = true;
  BusSetup host = kFd1And5Mbit, drives = kFd1And5Mbit;
  host.role = BusRole::host;
  drives.role = BusRole::drives;
  const BusBudget shared = bus_budget(traffic, kFd1And5Mbit);
  const BusBudget on_host = bus_budget(traffic, host);
  const BusBudget on_drives = bus_budget(traffic, drives);
  EXPECT_NEAR(on_host.load + on_drives.load, shared.load, 1e-12);
  EXPECT_NEAR(on_drives.load, (4000 * 56.6 + 1000 * 105.6) / 1e6, 1e-9);
  EXPECT_EQ(on_drives.message_count, 2);
  EXPECT_EQ(line_of(on_host, "CABLE_FEEDBACK"), nullptr);
  EXPECT_NE(line_of(on_host, "TARGET_FD"), nullptr);
  // Classical drives' bus: CABLE_SETPOINT per segment.
  BusSetup classical_drives{hal::CanFormat::classical, {1000000, 0}, BusRole::drives};
  EXPECT_NEAR(bus_budget(traffic, classical_drives).load, 8000 * 135.0 / 1e6, 1e-12);
}

}  // namespace
}  // namespace cdcr::firmware::protocol
