// The C API (cdcr/cdcr.h) with CiA 402 drives: the integrator chooses the
// backend in cdcr_config.cia402_drives and carries the drives' buses in the
// drives_can callbacks; the drives are written to CiA 301/402 in C++
// (cia402_test_drive.hpp), eight on two buses. From power-up to RUN with
// the pose of the drives' positions (the same pose the C API gives for
// those lengths without drives), a drive's EMCY as a fault naming its node
// until cdcr_recover_drives(), and an error for each configuration it
// cannot use.

#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/cdcr.h>
#include <cdcr/firmware/canopen/frames.hpp>
#include <cdcr/firmware/runtime.hpp>
#include <cdcr/sim/virtual_can.hpp>

#include "cia402_test_drive.hpp"
#include "export/image_writer.hpp"
#include "synthetic_trained_model.hpp"

namespace cdcr::firmware::canopen {
namespace {

constexpr int kCables = 8;  // two segments of four
constexpr double kCountsPerMm = 2000.0;
constexpr double kHomingOffsetMm = 100.0;

std::vector<std::uint8_t> two_segment_image() {
  test_support::SyntheticModelOptions options;
  options.segments = 2;
  training::TrainedModel m = test_support::synthetic_trained_model(options);
  for (int k = 0; k < 6; ++k) {
    m.output_mean[k] *= k < 3 ? 0.1 : 0.001;
    m.output_scale[k] *= k < 3 ? 0.1 : 0.001;
  }
  return exporting::write_image(m);
}

// Lengths of a bent robot on the protocol's 0.01 mm steps: a drive at
// 2,000 counts a millimetre holds each exactly.
std::vector<float> bent_cables(int segments) {
  model::RobotGeometry<double, kMaxSegments> g = Geometry::uniform(segments, 120.0f, 67.0f, 1.5707963f).cast<double>();
  model::JointVector<double, kMaxSegments> joints(2 * segments);
  for (int s = 0; s < segments; ++s) {
    joints[2 * s] = 0.7 * (s + 1);
    joints[2 * s + 1] = 0.15;
  }
  model::CableVector<double, kMaxSegments> cables;
  EXPECT_EQ(model::cables_from_joints(joints, g, cables), model::Status::ok);
  std::vector<float> out;
  for (int i = 0; i < cables.size(); ++i) out.push_back(float(std::round(cables[i] * 100.0) / 100.0));
  return out;
}

class CApiCia402 : public ::testing::Test {
 protected:
  void SetUp() override {
    image = two_segment_image();
    lengths = bent_cables(2);
    drives_config.drive_count = kCables;
    drives_config.bus_count = 2;
    drives_config.heartbeat_ms = 20;
    drives_config.max_speed_mm_per_s = 50.0f;
    for (int i = 0; i < kCables; ++i) {
      // Every other drive counts down as its cable lengthens.
      const double sign = (i % 2) ? -1.0 : 1.0;
      drives_config.drives[i] = {i / 4, i % 4 + 1, float(sign * kCountsPerMm), float(kHomingOffsetMm)};
      drives[i].node = NodeId(i % 4 + 1);
      drives[i].position = std::round((double(lengths[i]) - kHomingOffsetMm) * sign * kCountsPerMm);
    }
    config.model_image = image.data();
    config.model_image_size = std::uint32_t(image.size());
    config.fallback_geometry = cdcr_geometry{2, 120.0f, 67.0f, 1.5707963f, 0};
    config.period_ns = 1'000'000;
    config.callbacks.user = this;
    config.callbacks.now_ns = [](void* user) { return static_cast<CApiCia402*>(user)->now_ns; };
    config.callbacks.drives_can_send = [](void* user, int bus, const cdcr_can_frame* frame) {
      return static_cast<CApiCia402*>(user)->send(bus, *frame);
    };
    config.callbacks.drives_can_receive = [](void* user, int bus, cdcr_can_frame* frame) {
      return static_cast<CApiCia402*>(user)->receive(bus, *frame);
    };
    config.cia402_drives = &drives_config;
  }

  int send(int bus, const cdcr_can_frame& in) {
    if (bus < 0 || bus > 1) return ++wrong_bus, 1;
    hal::CanFrame frame;
    frame.id = in.id;
    frame.dlc = in.dlc;
    for (int i = 0; i < 8; ++i) frame.data[i] = in.data[i];
    return buses[bus].node(0).send(frame) == hal::CanStatus::ok ? 0 : 1;
  }
  int receive(int bus, cdcr_can_frame& out) {
    if (bus < 0 || bus > 1) return ++wrong_bus, 0;
    hal::CanFrame frame;
    if (buses[bus].node(0).receive(frame) != hal::CanStatus::ok) return 0;
    out.id = frame.id;
    out.dlc = frame.dlc;
    for (int i = 0; i < 8; ++i) out.data[i] = frame.data[i];
    return 1;
  }

  // One step of the runtime, then a millisecond of the drives.
  void step() {
    ASSERT_EQ(cdcr_step(&runtime), CDCR_OK);
    now_ns += 1'000'000;
    hal::CanFrame frame;
    for (int b = 0; b < 2; ++b) {
      while (buses[b].node(1).receive(frame) == hal::CanStatus::ok)
        for (int i = 4 * b; i < 4 * b + 4; ++i) drives[i].take(frame, buses[b].node(1));
      for (int i = 4 * b; i < 4 * b + 4; ++i) drives[i].tick(buses[b].node(1));
    }
  }
  cdcr_status status() {
    cdcr_status s{};
    EXPECT_EQ(cdcr_get_status(&runtime, &s), CDCR_OK);
    return s;
  }
  // Steps until RUN with a pose; how many, or -1.
  int steps_until_running(int limit) {
    cdcr_pose pose{};
    for (int n = 1; n <= limit; ++n) {
      step();
      if (status().state == CDCR_STATE_RUN && cdcr_get_pose(&runtime, &pose) == CDCR_OK) return n;
    }
    return -1;
  }

  std::vector<std::uint8_t> image;
  std::vector<float> lengths;
  cdcr_cia402_config drives_config{};
  cdcr_config config{};
  cdcr_runtime runtime{};
  sim::VirtualCanBus buses[2];
  TestDrive drives[kCables];
  std::int64_t now_ns = 0;
  int wrong_bus = 0;
};

TEST_F(CApiCia402, FromPowerUpToThePoseOfTheDrivesPositions) {
  ASSERT_EQ(cdcr_init(&runtime, &config), CDCR_OK);
  const int steps = steps_until_running(2000);
  ASSERT_GT(steps, 0) << cdcr_fault_name(status().fault) << ", detail " << int(status().fault_detail);
  for (const TestDrive& drive : drives) EXPECT_EQ(drive.statusword, 0x0237) << "node " << int(drive.node);
  // Every drive configured for the cycle: CSP mode, the period, the heartbeat.
  for (const TestDrive& drive : drives) {
    EXPECT_EQ(drive.objects.at(0x606000), 8u);
    EXPECT_EQ(drive.objects.at(0x100600), 1000u);
    EXPECT_EQ(drive.objects.at(0x101700), 20u);
  }
  EXPECT_EQ(wrong_bus, 0);
  EXPECT_EQ(cdcr_set_cable_lengths(&runtime, lengths.data(), lengths.size()), CDCR_ERROR_NOT_APPLICABLE);
  EXPECT_EQ(cdcr_set_segment_cable_lengths(&runtime, 0, lengths.data()), CDCR_ERROR_NOT_APPLICABLE);

  // The same lengths given by call, to a runtime without drives.
  cdcr_pose pose{}, expected{};
  ASSERT_EQ(cdcr_get_pose(&runtime, &pose), CDCR_OK);
  cdcr_config plain = config;
  plain.cia402_drives = nullptr;
  static cdcr_runtime reference;
  ASSERT_EQ(cdcr_init(&reference, &plain), CDCR_OK);
  ASSERT_EQ(cdcr_set_cable_lengths(&reference, lengths.data(), lengths.size()), CDCR_OK);
  ASSERT_EQ(cdcr_step(&reference), CDCR_OK);
  ASSERT_EQ(cdcr_get_pose(&reference, &expected), CDCR_OK);
  EXPECT_EQ(pose.compensated, 1);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(pose.position_mm[i], expected.position_mm[i], 1e-3) << i;
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(pose.quaternion[i], expected.quaternion[i], 1e-6) << i;
  EXPECT_EQ(cdcr_recover_drives(&reference), CDCR_ERROR_NOT_APPLICABLE);
}

TEST_F(CApiCia402, EmergencyIsAFaultNamingTheNodeUntilRecovered) {
  ASSERT_EQ(cdcr_init(&runtime, &config), CDCR_OK);
  ASSERT_GT(steps_until_running(2000), 0);
  drives[6].fault(buses[1].node(1), 0x2310);  // bus 1, node 3
  for (int n = 0; n < 3; ++n) step();
  EXPECT_EQ(status().state, CDCR_STATE_FAULT);
  EXPECT_EQ(status().fault, CDCR_FAULT_DRIVE_FAULT);
  EXPECT_EQ(status().fault_detail, 3);
  cdcr_pose pose{};
  EXPECT_EQ(cdcr_get_pose(&runtime, &pose), CDCR_ERROR_NO_DATA);
  for (int n = 0; n < 50; ++n) step();
  EXPECT_EQ(status().state, CDCR_STATE_FAULT);
  ASSERT_EQ(cdcr_recover_drives(&runtime), CDCR_OK);
  ASSERT_GT(steps_until_running(2000), 0) << cdcr_fault_name(status().fault);
  EXPECT_EQ(drives[6].statusword, 0x0237);
}

TEST_F(CApiCia402, ConfigurationsItCannotUseAreRefused) {
  const cdcr_cia402_config good = drives_config;
  const auto refused = [&](const char* what) {
    EXPECT_EQ(cdcr_init(&runtime, &config), CDCR_ERROR_INVALID_ARGUMENT) << what;
    drives_config = good;
    config.period_ns = 1'000'000;
  };
  drives_config.drives[3].node = 0;
  refused("node 0");
  drives_config.drives[3].node = 128;
  refused("node 128");
  drives_config.drives[5].node = drives_config.drives[4].node;
  refused("one node twice on a bus");
  drives_config.drives[2].bus = 2;
  refused("a bus beyond bus_count");
  drives_config.bus_count = 5;
  refused("five buses");
  drives_config.drive_count = 0;
  refused("no drives");
  drives_config.drive_count = CDCR_MAX_CABLES + 1;
  refused("more drives than cables");
  drives_config.drives[1].counts_per_mm = 0.0f;
  refused("zero counts per mm");
  drives_config.drives[1].homing_offset_mm = NAN;
  refused("a NaN offset");
  drives_config.sync_window_us = 2000;
  refused("a SYNC window beyond the period");
  drives_config.max_speed_mm_per_s = -1.0f;
  refused("a negative speed");
  config.period_ns = 0;
  refused("no period");
  config.period_ns = 1'000'500;
  refused("a period of no whole microseconds");
  EXPECT_EQ(cdcr_init(&runtime, &config), CDCR_OK);
}

}  // namespace
}  // namespace cdcr::firmware::canopen
