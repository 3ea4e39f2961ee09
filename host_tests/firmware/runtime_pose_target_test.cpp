// A pose target travels the whole way: planner frames -> runtime decode ->
// compensated IK -> setpoint frames. The setpoints, decoded from the bus and
// run back through the runtime's own forward path, must reach the target's
// orientation as well as its position; a rotation that is not symmetric
// (its axis has x, y and z components) shows any convention slip in the
// quaternion's decode (conjugate, component order, sign).

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "runtime_test_fixture.hpp"

namespace cdcr::firmware {
namespace {

namespace protocol = firmware::protocol;
using test_support::RuntimeTest;

// Where the runtime's own model puts the tip for a bent configuration of
// the test robot (the image's two segments): a pose it can reach.
model::Pose<double> reachable_pose(const Runtime& runtime, const model::JointVector<double>& joints) {
  const model::RobotGeometry<double> geometry = runtime.geometry().cast<double>();
  model::CableVector<double> cables;
  EXPECT_EQ(model::cables_from_joints(joints, geometry, cables), model::Status::ok);
  PoseEstimate estimate;
  EXPECT_EQ(runtime.estimate_pose(cables.cast<Scalar>(), estimate), model::Status::ok);
  EXPECT_TRUE(estimate.compensated);
  return estimate.pose.cast<double>();
}

TEST_F(RuntimeTest, PoseTargetSetpointsReachTheTargetOrientation) {
  boot(test_support::small_image());
  cycles(3);
  ASSERT_EQ(runtime->state(), RuntimeState::run);

  model::JointVector<double> joints(4);
  joints << 0.3, 0.35, 2.0, 0.4;  // alpha, theta of each segment
  const model::Pose<double> target = reachable_pose(*runtime, joints);
  const Eigen::AngleAxisd rotation(target.rotation);
  ASSERT_GT(rotation.angle(), 0.2);
  for (int i = 0; i < 3; ++i) ASSERT_GT(std::abs(rotation.axis()[i]), 0.1) << "axis " << rotation.axis().transpose();
  // Far from where the robot is, in both position and orientation.
  const model::PoseError<double> start_error =
      model::pose_error(runtime->latest_pose().pose.cast<double>(), target);
  ASSERT_GT(start_error.position_mm, 10.0);
  ASSERT_GT(start_error.orientation_rad, 0.1);

  host_frames();
  send_pose_target(target, 23);
  const int spent = cycles_until_ik_done();

  const std::vector<hal::CanFrame> frames = host_frames();
  protocol::IkReport report;
  ASSERT_TRUE(last_of(frames, report));
  EXPECT_EQ(report.sequence, 23);
  ASSERT_EQ(report.outcome, protocol::IkOutcome::converged);
  EXPECT_EQ(report.cycles, spent);
  EXPECT_LE(spent, 60);
  EXPECT_LE(report.position_residual_mm, double(kIkAcceptedPositionErrorMm));
  EXPECT_LE(report.orientation_residual_rad, double(kIkAcceptedOrientationErrorRad));

  // The setpoints as the drives receive them.
  Cables setpoints(4 * runtime->geometry().segment_count);
  int segments_seen = 0;
  for (const hal::CanFrame& frame : frames) {
    protocol::CableSetpoint setpoint;
    if (protocol::decode(frame, setpoint) != protocol::DecodeStatus::ok) continue;
    ASSERT_LT(setpoint.segment, runtime->geometry().segment_count);
    for (int k = 0; k < 4; ++k) setpoints[4 * setpoint.segment + k] = Scalar(setpoint.lengths_mm[k]);
    ++segments_seen;
  }
  ASSERT_EQ(segments_seen, runtime->geometry().segment_count);

  PoseEstimate reached;
  ASSERT_EQ(runtime->estimate_pose(setpoints, reached), model::Status::ok);
  const model::PoseError<double> error = model::pose_error(reached.pose.cast<double>(), target);
  EXPECT_LT(error.position_mm, 0.05);
  EXPECT_LT(error.orientation_rad, 1e-3);
}

}  // namespace
}  // namespace cdcr::firmware
