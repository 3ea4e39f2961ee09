// IK spread over cycles: while a request runs, every cycle still publishes
// the pose; a newer target supersedes a running one; a fault aborts it; each
// ending is reported with its sequence.

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
