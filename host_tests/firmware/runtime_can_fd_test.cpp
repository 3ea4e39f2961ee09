// The runtime on a CAN FD bus and on two buses: every frame it sends in the
// bus's format, the pose with its radii in one POSE_FD, the setpoints of up
// to four segments in one CABLE_SETPOINTS_FD, a whole target taken from one
// TARGET_FD; with a drives bus, the drives' traffic on it and the host's on
// the other. What the frames say is checked against the classical run of
// the same robot: the format changes the framing, never the numbers.

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "runtime_test_fixture.hpp"
#include "../support/variance_block.hpp"

namespace cdcr::firmware {
namespace {

namespace protocol = firmware::protocol;
using hal::CanFormat;
using test_support::RuntimeTest;

std::vector<std::uint8_t> image_with_radii() {
  training::TrainedModel m = test_support::small_correction_model(200);
  test_support::add_variance_block(m, 16);
  return exporting::write_image(m);
}

bool is_pose_frame(const hal::CanFrame& frame) { return (frame.id & 0x7F8) == 0x130; }

class RuntimeCanFdTest : public RuntimeTest {
 protected:
  // The runtime on an FD bus, its frames in `format`.
  void boot_fd(const std::vector<std::uint8_t>& image, CanFormat format = CanFormat::fd_bit_rate_switch) {
    make_platform(image);
    platform->bus.set_fd(true);
    start_runtime(platform->hal, format, format);
  }

  void listen_to_poses() {
    const hal::CanFilter filters[] = {protocol::kPoseFrames, protocol::kStatusFrames};
    platform->host_node.set_filters(filters, 2);
  }

  void send_target_fd(const Eigen::Vector3d& position_mm, std::uint8_t sequence, int dlc = 24) {
    protocol::TargetFd target;
    target.orientation = {1, 0, 0, 0};
    target.position_xy = {position_mm.x(), position_mm.y()};
    target.position_z = {position_mm.z(), protocol::TargetMode::position, false, sequence};
    hal::CanFrame frame;
    protocol::encode(target, frame);
    frame.flags = hal::kCanFdFrame | hal::kCanBitRateSwitch;
    frame.dlc = static_cast<std::uint8_t>(dlc);
    send(frame);
  }

  // A target a few millimetres from the pose the runtime estimates.
  Eigen::Vector3d near_target() const {
    return (runtime->latest_pose().pose.position_mm + model::Vec3<Scalar>(4, -3, 0)).cast<double>();
  }

  // The segments' setpoints among `frames`, whichever message carried them;
  // `frames_seen` counts the frames.
  static std::vector<protocol::CableSetpoint> setpoints_of(const std::vector<hal::CanFrame>& frames, int& frames_seen) {
    std::vector<protocol::CableSetpoint> setpoints;
    frames_seen = 0;
    for (const hal::CanFrame& frame : frames) {
      protocol::CableSetpoint one;
      protocol::CableSetpointsFd fd;
      if (protocol::decode(frame, one) == protocol::DecodeStatus::ok) {
        setpoints.push_back(one);
        ++frames_seen;
      } else if (protocol::decode(frame, fd) == protocol::DecodeStatus::ok) {
        for (int k = 0; k < fd.segment_count; ++k) setpoints.push_back(fd.segments[k]);
        ++frames_seen;
      }
    }
    return setpoints;
  }
};

TEST_F(RuntimeCanFdTest, EveryFrameGoesOutInTheBusFormat) {
  boot_fd(test_support::small_image());
  EXPECT_EQ(runtime->host_can_format(), CanFormat::fd_bit_rate_switch);
  EXPECT_EQ(runtime->drives_can_format(), CanFormat::fd_bit_rate_switch);
  const hal::CanFilter everything{0, 0};
  platform->host_node.set_filters(&everything, 1);
  cycles(30);
  const std::vector<hal::CanFrame> frames = host_frames();
  int runtime_frames = 0;
  for (const hal::CanFrame& frame : frames) {
    if ((frame.id & 0x7F8) == 0x100) continue;  // the drives' CABLE_FEEDBACK
    ++runtime_frames;
    EXPECT_TRUE(frame.fd()) << std::hex << frame.id;
    EXPECT_TRUE(frame.bit_rate_switch()) << std::hex << frame.id;
  }
  EXPECT_GT(runtime_frames, 30);
}

TEST_F(RuntimeCanFdTest, ThePoseIsOnePoseFdFrameACycleWithTheRadiiOnceKnown) {
  boot_fd(image_with_radii(), CanFormat::fd);
  listen_to_poses();
  int without_radii = 0;
  int with_radii = 0;
  std::uint8_t last_sequence = 0;
  for (int cycle = 0; cycle < 60; ++cycle) {
    // The pose goes out before the cycle's variance slice: with the radii
    // known when the cycle began.
    const bool radii_known = runtime->has_uncertainty();
    const model::PoseUncertainty<Scalar> radii = radii_known ? runtime->latest_uncertainty() : model::PoseUncertainty<Scalar>{};
    cycles(1);
    int pose_frames = 0;
    for (const hal::CanFrame& frame : host_frames()) {
      if (!is_pose_frame(frame)) continue;
      ++pose_frames;
      EXPECT_TRUE(frame.fd());
      EXPECT_FALSE(frame.bit_rate_switch());  // fd: no switch
      protocol::PoseFd pose;
      ASSERT_EQ(protocol::decode(frame, pose), protocol::DecodeStatus::ok) << std::hex << frame.id;
      const model::Pose<Scalar>& estimate = runtime->latest_pose().pose;
      EXPECT_NEAR(pose.position_xy.x_mm, estimate.position_mm.x(), 0.01);
      EXPECT_NEAR(pose.position_xy.y_mm, estimate.position_mm.y(), 0.01);
      EXPECT_NEAR(pose.position_z.z_mm, estimate.position_mm.z(), 0.01);
      if (cycle > 0) {
        EXPECT_EQ(pose.position_z.sequence, static_cast<std::uint8_t>(last_sequence + 1));
      }
      last_sequence = pose.position_z.sequence;
      EXPECT_EQ(pose.position_z.radii, radii_known);
      if (!pose.position_z.radii) {
        ++without_radii;
        continue;
      }
      ++with_radii;
      EXPECT_NEAR(pose.uncertainty.r95_position_mm, radii.r95_mm, 0.01);
      EXPECT_NEAR(pose.uncertainty.r95_orientation_deg, radii.r95_deg, 0.01);
    }
    EXPECT_EQ(pose_frames, 1) << "cycle " << cycle;  // one POSE_FD, no classical pose frame and no POSE_UNCERTAINTY
  }
  EXPECT_GT(without_radii, 0);  // the first cycles, before the variance's first slices end
  EXPECT_GT(with_radii, 30);
}

// The same target to the same robot, classical and FD: the same IK report
// and the same setpoints, one CABLE_SETPOINTS_FD frame for both segments
// instead of a CABLE_SETPOINT each.
TEST_F(RuntimeCanFdTest, ATargetFdGivesTheSetpointsOfTheClassicalFrames) {
  std::vector<protocol::CableSetpoint> classical_setpoints;
  Eigen::Vector3d target;
  protocol::IkReport classical_report;
  int classical_frames = 0;
  {
    boot(test_support::small_image());
    cycles(5);
    host_frames();
    target = near_target();
    send_position_target(target.x(), target.y(), target.z(), 7);
    cycles_until_ik_done();
    const std::vector<hal::CanFrame> frames = host_frames();
    ASSERT_TRUE(last_of(frames, classical_report));
    classical_setpoints = setpoints_of(frames, classical_frames);
  }
  boot_fd(test_support::small_image());
  cycles(5);
  host_frames();
  EXPECT_EQ(near_target(), target);
  send_target_fd(target, 7);
  cycles_until_ik_done();
  const std::vector<hal::CanFrame> frames = host_frames();
  protocol::IkReport report;
  ASSERT_TRUE(last_of(frames, report));
  EXPECT_EQ(report.sequence, 7);
  EXPECT_EQ(classical_report.outcome, protocol::IkOutcome::converged);
  EXPECT_EQ(report.outcome, classical_report.outcome);
  EXPECT_EQ(report.iterations, classical_report.iterations);
  EXPECT_EQ(report.position_residual_mm, classical_report.position_residual_mm);
  int fd_frames = 0;
  const std::vector<protocol::CableSetpoint> setpoints = setpoints_of(frames, fd_frames);
  ASSERT_EQ(setpoints.size(), 2u);
  ASSERT_EQ(classical_setpoints.size(), 2u);
  EXPECT_EQ(classical_frames, 2);
  EXPECT_EQ(fd_frames, 1);
  for (int s = 0; s < 2; ++s) {
    EXPECT_EQ(setpoints[s].segment, s);
    for (int c = 0; c < 4; ++c) {
      EXPECT_EQ(setpoints[s].lengths_mm[c], classical_setpoints[s].lengths_mm[c]) << "segment " << s << " cable " << c;
    }
  }
  // The drives took them.
  cycles(1);
  EXPECT_EQ(drives->rejected_frames(), 0u);
  EXPECT_NEAR(drives->setpoints_mm()[0], setpoints[0].lengths_mm[0], 1e-9);
  EXPECT_NEAR(drives->setpoints_mm()[7], setpoints[1].lengths_mm[3], 1e-9);
}

TEST_F(RuntimeCanFdTest, AMalformedTargetFdIsRejectedAndStartsNothing) {
  boot_fd(test_support::small_image());
  cycles(5);
  const std::uint64_t rejected = runtime->statistics().rejected_frames;
  send_target_fd({20.0, -15.0, 215.0}, 3, 32);  // a length TARGET_FD does not have
  cycles(1);
  EXPECT_FALSE(runtime->ik_running());
  EXPECT_EQ(runtime->statistics().rejected_frames, rejected + 1);

  // Bits set in a part's unused bytes (TARGET_POSITION_Z's last two).
  protocol::TargetFd target;
  target.orientation = {1, 0, 0, 0};
  target.position_xy = {20.0, -15.0};
  target.position_z = {215.0, protocol::TargetMode::position, false, 4};
  hal::CanFrame frame;
  protocol::encode(target, frame);
  frame.flags = hal::kCanFdFrame | hal::kCanBitRateSwitch;
  frame.data[2 * 8 + 7] = 0x01;
  send(frame);
  cycles(1);
  EXPECT_FALSE(runtime->ik_running());
  EXPECT_EQ(runtime->statistics().rejected_frames, rejected + 2);
}

TEST_F(RuntimeCanFdTest, FdFormatsAreRefusedWhereTheyCannotHold) {
  make_platform(test_support::small_image());
  Runtime on_classical(platform->hal, Geometry::uniform(2, 120.0f, 67.0f));
  EXPECT_FALSE(on_classical.set_can_formats(CanFormat::fd, CanFormat::fd));  // the controller has no FD
  EXPECT_EQ(on_classical.host_can_format(), CanFormat::classical);
  EXPECT_TRUE(on_classical.set_can_formats(CanFormat::classical, CanFormat::classical));

  platform->bus.set_fd(true);
  Runtime on_fd(platform->hal, Geometry::uniform(2, 120.0f, 67.0f));
  // One bus: one format.
  EXPECT_FALSE(on_fd.set_can_formats(CanFormat::classical, CanFormat::fd));
  EXPECT_EQ(on_fd.drives_can_format(), CanFormat::classical);
  EXPECT_TRUE(on_fd.set_can_formats(CanFormat::fd, CanFormat::fd));
  on_fd.init();
  // Kept across init(), and not changed once running.
  EXPECT_EQ(on_fd.host_can_format(), CanFormat::fd);
  EXPECT_FALSE(on_fd.set_can_formats(CanFormat::fd_bit_rate_switch, CanFormat::fd_bit_rate_switch));
  EXPECT_EQ(on_fd.host_can_format(), CanFormat::fd);
}

// The drives on a bus of their own (classical), the host on an FD bus.
class RuntimeTwoBusTest : public RuntimeCanFdTest {
 protected:
  void boot_two_buses(CanFormat host, CanFormat drives_format) {
    make_platform(test_support::small_image());
    platform->bus.set_fd(true);
    drives_bus.set_fd(drives_format != CanFormat::classical);
    hal::Hal hal = platform->hal;
    hal.drives_can = &drives_bus.node(0);
    start_runtime(hal, host, drives_format, &drives_bus.node(1));
    const hal::CanFilter everything{0, 0};
    drives_listener().set_filters(&everything, 1);
  }
  hal::CanBus& drives_listener() { return drives_bus.node(2); }
  std::vector<hal::CanFrame> drives_frames() {
    std::vector<hal::CanFrame> frames;
    hal::CanFrame frame;
    while (drives_listener().receive(frame) == hal::CanStatus::ok) frames.push_back(frame);
    return frames;
  }

  sim::VirtualCanBus drives_bus;
};

TEST_F(RuntimeTwoBusTest, TheDrivesTrafficIsOnTheirBusAndTheHostsOnTheOther) {
  boot_two_buses(CanFormat::fd_bit_rate_switch, CanFormat::classical);
  ASSERT_TRUE(runtime->has_drives_bus());
  EXPECT_TRUE(runtime->can_filters_accepted());
  const hal::CanFilter everything{0, 0};
  platform->host_node.set_filters(&everything, 1);
  cycles(5);
  EXPECT_EQ(runtime->state(), RuntimeState::run);  // the drives' feedback arrives on their bus
  host_frames();
  drives_frames();
  send_target_fd(near_target(), 9);
  cycles_until_ik_done();
  cycles(2);

  const std::vector<hal::CanFrame> on_host = host_frames();
  const std::vector<hal::CanFrame> on_drives = drives_frames();
  protocol::IkReport report;
  ASSERT_TRUE(last_of(on_host, report));
  EXPECT_EQ(report.sequence, 9);
  int host_setpoint_frames = 0;
  int drives_setpoint_frames = 0;
  EXPECT_TRUE(setpoints_of(on_host, host_setpoint_frames).empty());
  const std::vector<protocol::CableSetpoint> setpoints = setpoints_of(on_drives, drives_setpoint_frames);
  ASSERT_FALSE(setpoints.empty());
  EXPECT_EQ(drives_setpoint_frames, static_cast<int>(setpoints.size()));  // classical: one frame a segment
  for (const hal::CanFrame& frame : on_drives) {
    EXPECT_FALSE(frame.fd());
    EXPECT_FALSE(is_pose_frame(frame)) << std::hex << frame.id;
    EXPECT_NE(frame.id & 0x7FE, 0x150u);  // no STATUS, STATS
  }
  int poses = 0;
  for (const hal::CanFrame& frame : on_host) {
    poses += is_pose_frame(frame) ? 1 : 0;
    EXPECT_TRUE(frame.fd()) << std::hex << frame.id;
  }
  EXPECT_GT(poses, 0);
  EXPECT_EQ(drives->rejected_frames(), 0u);
  const protocol::CableSetpoint& last = setpoints.back();
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(drives->setpoints_mm()[4 * last.segment + c], last.lengths_mm[c], 1e-9);
}

TEST_F(RuntimeTwoBusTest, CableFeedbackOnTheHostBusIsNotTaken) {
  boot_two_buses(CanFormat::classical, CanFormat::fd_bit_rate_switch);
  cycles(5);
  const model::Pose<Scalar> before = runtime->latest_pose().pose;
  // The drives fall silent and someone on the host's bus sends lengths of
  // another bend for both segments: they are not the drives', so the
  // cables go stale and the runtime faults, its pose where it was.
  drives->set_silent(true);
  hal::CanFrame frames[2];
  ASSERT_TRUE(protocol::encode(protocol::CableFeedback{0, {100.0, 140.0, 100.0, 140.0}}, frames[0]));
  ASSERT_TRUE(protocol::encode(protocol::CableFeedback{1, {100.0, 140.0, 100.0, 140.0}}, frames[1]));
  for (int k = 0; k < kStaleInputCycles + 2; ++k) {
    for (const hal::CanFrame& frame : frames) send(frame);
    cycles(1);
  }
  EXPECT_EQ(runtime->state(), RuntimeState::fault);
  EXPECT_LT((runtime->latest_pose().pose.position_mm - before.position_mm).norm(), 1e-6);
  drives->set_silent(false);
  cycles(2);
  ASSERT_EQ(runtime->state(), RuntimeState::run);
  EXPECT_EQ(runtime->statistics().rejected_frames, 0u);
  // And the setpoints go out as FD on the drives' bus.
  const Eigen::Vector3d target = near_target();
  send_position_target(target.x(), target.y(), target.z(), 2);
  cycles_until_ik_done();
  int frames_seen = 0;
  const std::vector<hal::CanFrame> on_drives = drives_frames();
  const std::size_t setpoint_count = setpoints_of(on_drives, frames_seen).size();
  EXPECT_EQ(setpoint_count, 2u * static_cast<std::size_t>(frames_seen));  // both segments in each FD frame
  EXPECT_GT(frames_seen, 0);
  for (const hal::CanFrame& frame : on_drives) {
    if ((frame.id & 0x7F8) == 0x118) {
      EXPECT_TRUE(frame.fd() && frame.bit_rate_switch());
    }
  }
}

}  // namespace
}  // namespace cdcr::firmware
