// IK spread over cycles: while a request runs, every cycle still publishes
// the pose; a newer target supersedes a running one; a fault aborts it; each
// ending is reported with its sequence.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "runtime_test_fixture.hpp"

namespace cdcr::firmware {
namespace {

namespace protocol = firmware::protocol;
using test_support::RuntimeTest;

std::vector<protocol::IkReport> reports_in(const std::vector<hal::CanFrame>& frames) {
  std::vector<protocol::IkReport> reports;
  for (const hal::CanFrame& frame : frames) {
    protocol::IkReport report;
    if (protocol::decode(frame, report) == protocol::DecodeStatus::ok) reports.push_back(report);
  }
  return reports;
}

class IkCyclesTest : public RuntimeTest {
 protected:
  void SetUp() override {
    boot(test_support::multi_cycle_image());
    cycles(3);
    ASSERT_EQ(runtime->state(), RuntimeState::run);
    // Less than one evaluation of the model per cycle: requests span cycles.
    ASSERT_LT(runtime->ik_units_per_cycle(), 3 * 600u);
    far_ = runtime->latest_pose().pose.position_mm.cast<double>() + Eigen::Vector3d(30, -20, -10);
    host_frames();
  }
  Eigen::Vector3d far_;
};

TEST_F(IkCyclesTest, PosePublishedEveryCycleWhileSolving) {
  send_position_target(far_.x(), far_.y(), far_.z(), 5);
  int spent = 0;
  do {
    const std::uint32_t before = runtime->statistics().poses_published;
    cycles(1);
    ++spent;
    ASSERT_EQ(runtime->statistics().poses_published, before + 1) << "cycle " << spent;
  } while (runtime->ik_running() && spent < kMaxIkCycles + 1);
  EXPECT_GT(spent, 1);
  const std::vector<protocol::IkReport> reports = reports_in(host_frames());
  ASSERT_FALSE(reports.empty());
  EXPECT_EQ(reports.back().sequence, 5);
  EXPECT_EQ(reports.back().outcome, protocol::IkOutcome::converged);
  EXPECT_EQ(reports.back().cycles, spent);
  // In-progress reports, one every kIkProgressEveryCycles cycles, before it.
  EXPECT_EQ(int(reports.size()) - 1, (spent - 1) / kIkProgressEveryCycles);
  for (std::size_t i = 0; i + 1 < reports.size(); ++i) {
    EXPECT_EQ(reports[i].outcome, protocol::IkOutcome::in_progress);
    EXPECT_EQ(reports[i].cycles, int(i + 1) * kIkProgressEveryCycles);
  }
}

// A planner streams a TRACKING target every cycle along a circle at 100 mm/s
// (0.1 mm a cycle): every cycle after the first 3 sends setpoints, and the
// setpoints the drives hold stay within 3 cycles of path behind the newest
// target, every time. The circle lies
// inside the workspace (a target the robot cannot reach is not followed,
// by the policy), which a cold solve checks on the way.
TEST_F(IkCyclesTest, StreamedTargetsAreFollowedWithinThreeCycles) {
  const auto tip_of = [&](const Joints& joints) -> Eigen::Vector3d {
    const Joints bend = model::bend_from_joints(joints);
    return (model::exp(runtime->correction().predict(bend)) * model::forward_kinematics_bend(bend, runtime->geometry()))
        .position_mm.cast<double>();
  };
  constexpr double kRadiusMm = 10.0, kPathPerCycleMm = 0.1;
  // The height at which the robot, every segment bent the same way, reaches
  // three radii off its axis; the circle's centre half a radius off it.
  const int segments = runtime->geometry().segment_count;
  Joints equal_bend(2 * segments);
  double low = 0, high = 1;
  Eigen::Vector3d rim;
  for (int i = 0; i < 40; ++i) {
    for (int s = 0; s < segments; ++s) equal_bend.segment<2>(2 * s) << 0.0f, float(0.5 * (low + high));
    rim = model::forward_kinematics_bend(model::bend_from_joints(equal_bend), runtime->geometry())
              .position_mm.cast<double>();
    (rim.head<2>().norm() < 3 * kRadiusMm ? low : high) = 0.5 * (low + high);
  }
  const Eigen::Vector3d center(0.5 * kRadiusMm, 0, rim.z());
  const auto on_circle = [&](int step) {
    const double angle = kPathPerCycleMm / kRadiusMm * step;
    return Eigen::Vector3d(center + kRadiusMm * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0));
  };
  Solver cold;
  SolverCorrection cold_correction(runtime->correction());
  cold.configure(runtime->geometry(), cold_correction);
  Joints slight_bend(2 * segments);
  for (int s = 0; s < segments; ++s) slight_bend.segment<2>(2 * s) << 0.0f, 0.1f;
  send_position_target(on_circle(0).x(), on_circle(0).y(), on_circle(0).z(), 1);
  cycles_until_ik_done();
  protocol::IkReport first;
  ASSERT_TRUE(last_ik_report(first));
  ASSERT_EQ(first.outcome, protocol::IkOutcome::converged);
  Eigen::Vector3d held = tip_of(runtime->setpoint_joints());
  ASSERT_LT((held - on_circle(0)).norm(), 0.01);
  std::vector<double> lag_cycles;
  const std::uint32_t setpoints_before = runtime->setpoints_published();
  constexpr int kSteps = 630;  // once round the circle
  for (int step = 1; step <= kSteps; ++step) {
    const Eigen::Vector3d target = on_circle(step);
    if (step % 63 == 0) {
      model::Pose<float> on_path;
      on_path.position_mm = target.cast<float>();
      cold.start(on_path, model::IkTargetKind::position, slight_bend);
      ASSERT_EQ(cold.run_to_end(), model::IkSolveState::converged) << "step " << step << " is out of reach";
    }
    send_frame(protocol::TargetPositionXy{target.x(), target.y()});
    send_frame(protocol::TargetPositionZ{target.z(), protocol::TargetMode::position, true,
                                         static_cast<std::uint8_t>(step)});
    const std::uint32_t before = runtime->setpoints_published();
    cycles(1);
    const bool sent = runtime->setpoints_published() != before;
    if (sent) held = tip_of(runtime->setpoint_joints());
    if (step > 3) EXPECT_TRUE(sent) << "no setpoints in the cycle of streamed target " << step;
    if (step > 20) lag_cycles.push_back((held - target).norm() / kPathPerCycleMm);
  }
  EXPECT_GE(runtime->setpoints_published() - setpoints_before, unsigned(kSteps) - 3);
  std::sort(lag_cycles.begin(), lag_cycles.end());
  const double p99 = lag_cycles[lag_cycles.size() * 99 / 100];
  std::printf("streamed lag: p50 %.2f p99 %.2f max %.2f cycles of path\n", lag_cycles[lag_cycles.size() / 2], p99,
              lag_cycles.back());
  EXPECT_LE(lag_cycles.back(), 3.0);
}

TEST_F(IkCyclesTest, NewerTargetSupersedesTheRunningOne) {
  send_position_target(far_.x(), far_.y(), far_.z(), 6);
  cycles(1);
  ASSERT_TRUE(runtime->ik_running());
  send_position_target(far_.x() - 5, far_.y(), far_.z(), 7);
  cycles_until_ik_done();
  const std::vector<protocol::IkReport> reports = reports_in(host_frames());
  ASSERT_GE(reports.size(), 2u);
  EXPECT_EQ(reports.front().sequence, 6);
  EXPECT_EQ(reports.front().outcome, protocol::IkOutcome::superseded);
  EXPECT_EQ(reports.front().cycles, 1);
  EXPECT_EQ(reports.back().sequence, 7);
  EXPECT_EQ(reports.back().outcome, protocol::IkOutcome::converged);
}

TEST_F(IkCyclesTest, FaultAbortsTheRunningRequestAndHoldsTheSetpoints) {
  const std::uint32_t setpoints_before = runtime->setpoints_published();
  // One drive falls silent; the target arrives a cycle before the input
  // goes stale.
  drives->set_segment_silent(0, true);
  cycles(kStaleInputCycles - 1);
  ASSERT_EQ(runtime->state(), RuntimeState::run);
  send_position_target(far_.x(), far_.y(), far_.z(), 8);
  cycles(1);
  ASSERT_TRUE(runtime->ik_running());
  int waited = 0;
  while (runtime->state() != RuntimeState::fault && waited < 5 * kStaleInputCycles) {
    cycles(1);
    ++waited;
  }
  ASSERT_EQ(runtime->state(), RuntimeState::fault);
  EXPECT_FALSE(runtime->ik_running());
  EXPECT_EQ(runtime->setpoints_published(), setpoints_before);
  const std::vector<protocol::IkReport> reports = reports_in(host_frames());
  ASSERT_FALSE(reports.empty());
  EXPECT_EQ(reports.back().sequence, 8);
  EXPECT_EQ(reports.back().outcome, protocol::IkOutcome::aborted_fault);
}

}  // namespace
}  // namespace cdcr::firmware
