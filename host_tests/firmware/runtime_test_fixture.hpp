#pragma once
// The runtime tests' setting: the runtime on node 0 of the simulated bus, the
// simulated drives on node 1, and a host on node 2 that sends targets and
// hears IK_REPORT, STATUS, STATS and the cable setpoints, every frame through
// the protocol codec.

#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/firmware/protocol.hpp>

#include "runtime_fixture.hpp"

namespace cdcr::test_support {

class RuntimeTest : public ::testing::Test {
 protected:
  void boot(const std::vector<std::uint8_t>& image) {
    make_platform(image);
    start_runtime(platform->hal);
  }

  // In two steps, for a test that puts a controller double between the
  // runtime and its node of the bus.
  void make_platform(const std::vector<std::uint8_t>& image) { platform = std::make_unique<SimulatedPlatform>(image); }
  // `host_format` and `drives_format`: the runtime's frames on its buses
  // (Runtime::set_can_formats); `drives_node`: where the drives listen
  // (the platform's own node 1 unless the HAL has a drives bus).
  void start_runtime(const hal::Hal& hal, hal::CanFormat host_format = hal::CanFormat::classical,
                     hal::CanFormat drives_format = hal::CanFormat::classical, hal::CanBus* drives_node = nullptr) {
    runtime = std::make_unique<firmware::Runtime>(hal, firmware::Geometry::uniform(2, 120.0f, 67.0f));
    ASSERT_TRUE(runtime->set_can_formats(host_format, drives_format));
    runtime->init();
    drives = std::make_unique<sim::SimulatedCableDrives>(drives_node != nullptr ? *drives_node : platform->drives_node,
                                                         bent_cables(runtime->geometry()), 50.0,
                                                         sim::cables_per_segment(runtime->geometry()));
    const hal::CanFilter host_filters[] = {firmware::protocol::kIkReportFrames, firmware::protocol::kStatusFrames,
                                           firmware::protocol::kCableSetpointFrames,
                                           firmware::protocol::kCableSetpointsFdFrames};
    platform->host_node.set_filters(host_filters, 4);
  }

  void cycles(int count) {
    for (int i = 0; i < count; ++i) {
      const hal::TimerTick tick = platform->timer.wait_next();
      drives->step(1e-3);
      runtime->run_cycle(tick);
    }
  }

  // Runs cycles until the IK request in progress ends (its final IK_REPORT
  // is then on the bus); returns the cycles run.
  int cycles_until_ik_done(int limit = firmware::kMaxIkCycles + 1) {
    int count = 0;
    do {
      cycles(1);
      ++count;
    } while (runtime->ik_running() && count < limit);
    return count;
  }

  void send(const hal::CanFrame& frame) { ASSERT_EQ(platform->host_node.send(frame), hal::CanStatus::ok); }

  template <typename Frame>
  void send_frame(const Frame& message) {
    hal::CanFrame frame;
    firmware::protocol::encode(message, frame);
    send(frame);
  }

  void send_position_target(double x, double y, double z, std::uint8_t sequence) {
    send_frame(firmware::protocol::TargetPositionXy{x, y});
    send_frame(firmware::protocol::TargetPositionZ{z, firmware::protocol::TargetMode::position, false, sequence});
  }

  // The three frames of a pose target, as a planner sends them.
  void send_pose_target(const model::Pose<double>& target, std::uint8_t sequence) {
    Eigen::Quaterniond q(target.rotation);
    q.normalize();
    send_frame(firmware::protocol::TargetOrientation{q.w(), q.x(), q.y(), q.z()});
    send_frame(firmware::protocol::TargetPositionXy{target.position_mm.x(), target.position_mm.y()});
    send_frame(firmware::protocol::TargetPositionZ{target.position_mm.z(), firmware::protocol::TargetMode::pose, false,
                                                   sequence});
  }

  // Every frame the host heard since the last call.
  std::vector<hal::CanFrame> host_frames() {
    std::vector<hal::CanFrame> frames;
    hal::CanFrame frame;
    while (platform->host_node.receive(frame) == hal::CanStatus::ok) frames.push_back(frame);
    return frames;
  }

  // The last frame of that message among `frames`, decoded.
  template <typename Message>
  static bool last_of(const std::vector<hal::CanFrame>& frames, Message& message) {
    bool found = false;
    for (const hal::CanFrame& frame : frames) {
      found = firmware::protocol::decode(frame, message) == firmware::protocol::DecodeStatus::ok || found;
    }
    return found;
  }

  // The last IK_REPORT on the host's node, if any (draining the node).
  bool last_ik_report(firmware::protocol::IkReport& report) { return last_of(host_frames(), report); }

  std::unique_ptr<SimulatedPlatform> platform;
  std::unique_ptr<firmware::Runtime> runtime;
  std::unique_ptr<sim::SimulatedCableDrives> drives;
};

}  // namespace cdcr::test_support
