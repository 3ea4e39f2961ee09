// The simulated robot's drives as a hal::Drives backend (tools/sim/
// direct_drives.hpp) behind the runtime, with no image (nominal
// kinematics): the pose of their lengths as the model library gives it, a
// position target solved and followed to within 0.05 mm, an injected fault
// in STATUS with the drive's number until the host's DRIVES_COMMAND, and
// the backend's own refusals.

#include <memory>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/firmware/protocol.hpp>
#include <cdcr/firmware/runtime.hpp>
#include <cdcr/model/chain.hpp>

#include "sim/direct_drives.hpp"
#include "sim/simulated_platform.hpp"
#include "sim/target_frames.hpp"

namespace cdcr::sim {
namespace {

namespace protocol = firmware::protocol;
using firmware::FaultCode;
using firmware::RuntimeState;

model::JointVector<double> bent_joints(const model::RobotGeometry<double>& geometry, double theta_rad) {
  model::JointVector<double> joints(2 * geometry.segment_count);
  for (int s = 0; s < geometry.segment_count; ++s) {
    joints[2 * s] = 0.5 * (s + 1);
    joints[2 * s + 1] = theta_rad;
  }
  return joints;
}

std::vector<double> bent_cables(const model::RobotGeometry<double>& geometry, double theta_rad) {
  const model::JointVector<double> joints = bent_joints(geometry, theta_rad);
  model::CableVector<double> cables;
  EXPECT_EQ(model::cables_from_joints(joints, geometry, cables), model::Status::ok);
  return std::vector<double>(cables.data(), cables.data() + cables.size());
}

class DirectDrivesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    platform.timer.start(1'000'000);
    geometry = firmware::Geometry::prototype().cast<double>();
    drives = std::make_unique<DirectCableDrives>(bent_cables(geometry, 0.2), 50.0, 1e-3);
    hal::Hal hal = platform.hal;
    hal.drives = drives.get();
    runtime = std::make_unique<firmware::Runtime>(hal, firmware::Geometry::prototype());
    runtime->init();
  }
  void cycle() {
    runtime->run_cycle(platform.timer.wait_next());
    hal::CanFrame frame;
    while (platform.bus.node(1).receive(frame) == hal::CanStatus::ok) {
      protocol::IkReport report;
      if (protocol::decode(frame, report) == protocol::DecodeStatus::ok) last_report = report;
    }
  }
  void send(const hal::CanFrame& frame) { ASSERT_EQ(platform.bus.node(1).send(frame), hal::CanStatus::ok); }

  SimulatedPlatform platform;
  model::RobotGeometry<double> geometry;
  std::unique_ptr<DirectCableDrives> drives;
  std::unique_ptr<firmware::Runtime> runtime;
  protocol::IkReport last_report;
};

TEST_F(DirectDrivesTest, PoseOfTheirLengthsAndATargetFollowed) {
  for (int n = 0; n < 3; ++n) cycle();
  ASSERT_TRUE(runtime->has_pose());
  EXPECT_EQ(runtime->state(), RuntimeState::degraded);  // no image: nominal kinematics
  model::Pose<double> expected;
  ASSERT_EQ(model::forward_kinematics(bent_joints(geometry, 0.2), geometry, expected), model::Status::ok);
  EXPECT_LT((runtime->latest_pose().pose.position_mm.cast<double>() - expected.position_mm).norm(), 1e-3);

  // A target the robot reaches with other bends.
  model::Pose<double> goal;
  ASSERT_EQ(model::forward_kinematics(bent_joints(geometry, 0.35), geometry, goal), model::Status::ok);
  for (const hal::CanFrame& frame : target_frames(goal.position_mm, protocol::TargetMode::position, false, 9))
    send(frame);
  for (int n = 0; n < 3000; ++n) cycle();
  EXPECT_EQ(last_report.sequence, 9);
  EXPECT_EQ(last_report.outcome, protocol::IkOutcome::converged);
  for (std::size_t i = 0; i < drives->cables_mm().size(); ++i)
    EXPECT_NEAR(drives->cables_mm()[i], drives->setpoints_mm()[i], 1e-9) << "cable " << i;
  EXPECT_LT((runtime->latest_pose().pose.position_mm.cast<double>() - goal.position_mm).norm(), 0.05);
}

TEST_F(DirectDrivesTest, InjectedFaultUntilTheHostRecovers) {
  for (int n = 0; n < 3; ++n) cycle();
  drives->fail(5, hal::DrivesCondition::silent);
  cycle();
  EXPECT_EQ(runtime->state(), RuntimeState::fault);
  EXPECT_EQ(runtime->active_fault(), FaultCode::drive_silent);
  EXPECT_EQ(runtime->active_fault_detail(), firmware::FaultDetail::drive(6));
  for (int n = 0; n < 20; ++n) cycle();
  EXPECT_EQ(runtime->state(), RuntimeState::fault);
  hal::CanFrame command;
  protocol::encode(protocol::DrivesCommand{}, command);
  send(command);
  for (int n = 0; n < 3; ++n) cycle();
  EXPECT_EQ(runtime->state(), RuntimeState::degraded);
  EXPECT_EQ(drives->health().condition, hal::DrivesCondition::ready);

  drives->fail(2, hal::DrivesCondition::faulted);
  cycle();
  EXPECT_EQ(runtime->active_fault(), FaultCode::drive_fault);
  EXPECT_EQ(runtime->active_fault_detail(), firmware::FaultDetail::drive(3));
}

TEST(DirectDrives, RefusesWhatNoDriveTakes) {
  EXPECT_THROW(DirectCableDrives({}, 10.0, 1e-3), std::invalid_argument);
  EXPECT_THROW(DirectCableDrives({100.0}, 0.0, 1e-3), std::invalid_argument);
  DirectCableDrives drives({100.0, 101.0}, 10.0, 1e-3);
  double lengths[2] = {};
  EXPECT_FALSE(drives.lengths(lengths, 2)) << "before start";
  ASSERT_TRUE(drives.start());
  EXPECT_FALSE(drives.lengths(lengths, 3)) << "another cable count";
  const double negative[2] = {-1.0, 100.0};
  EXPECT_FALSE(drives.command(negative, 2));
  const double far[2] = {200.0, 50.0};
  ASSERT_TRUE(drives.command(far, 2));
  drives.receive();
  ASSERT_TRUE(drives.lengths(lengths, 2));
  // 10 mm/s for 1 ms: 0.01 mm a cycle, each way.
  EXPECT_NEAR(lengths[0], 100.01, 1e-12);
  EXPECT_NEAR(lengths[1], 100.99, 1e-12);
  EXPECT_FALSE(drives.recover()) << "nothing to recover";
  EXPECT_THROW(drives.fail(2, hal::DrivesCondition::silent), std::out_of_range);
}

}  // namespace
}  // namespace cdcr::sim
