// The runtime's predictive variance: spread over a few cycles within the
// cycle's work budget, sent as POSE_UNCERTAINTY for the pose it belongs to,
// equal to what the same code gives in one go, and the extrapolation flag
// in the pose frame and STATUS.

#include <algorithm>
#include <map>
#include <vector>

#include <gtest/gtest.h>

#include "runtime_test_fixture.hpp"
#include "train/predictive_variance.hpp"

namespace cdcr::firmware {
namespace {

namespace protocol = firmware::protocol;
using test_support::RuntimeTest;

// The fixture's small model with one kernel for every output and a variance
// factor of `rank` points over its rows.
std::vector<std::uint8_t> image_with_variance(int rank, double extrapolation_variance = 1.0, int points = 200) {
  training::TrainedModel m = test_support::small_correction_model(points);
  m.signal_variance.setConstant(m.signal_variance[0]);
  m.noise_variance.setConstant(m.noise_variance[0]);
  m.variance = training::fit_variance_factor(m, m.inputs, training::variance_points(m, m.inputs, rank, 1));
  m.variance.extrapolation_variance = extrapolation_variance;
  return exporting::write_image(m);
}

class RuntimeUncertaintyTest : public RuntimeTest {
 protected:
  void listen_to_poses() {
    const hal::CanFilter host_filters[] = {protocol::kPoseFrames, protocol::kStatusFrames};
    platform->host_node.set_filters(host_filters, 2);
  }
};

TEST_F(RuntimeUncertaintyTest, RadiiOfARecentPoseGoOutEveryFewCycles) {
  boot(image_with_variance(64));
  ASSERT_EQ(runtime->state(), RuntimeState::run);
  listen_to_poses();
  // The variance's slice comes out of IK's share of the cycle.
  EXPECT_EQ(runtime->ik_units_per_cycle(),
            kCycleWorkUnits - kWorkCosts.cycle_overhead - 200 - kUncertaintyUnitsPerCycle);

  std::map<std::uint8_t, model::Pose<float>> poses;  // by sequence, within the window
  std::vector<protocol::PoseUncertainty> radii;
  PoseEstimate latest;
  for (int cycle = 0; cycle < 40; ++cycle) {
    cycles(1);
    latest = runtime->latest_pose();
    for (const hal::CanFrame& frame : host_frames()) {
      protocol::PosePositionZ z;
      if (protocol::decode(frame, z) == protocol::DecodeStatus::ok) {
        EXPECT_FALSE(z.extrapolating);
        poses[z.sequence] = latest.pose;
      }
      protocol::PoseUncertainty u;
      if (protocol::decode(frame, u) == protocol::DecodeStatus::ok) radii.push_back(u);
    }
  }
  EXPECT_EQ(runtime->statistics().overruns, 0u);
  // 832 units at 192 a cycle: five slices, and the next evaluation starts
  // with the next cycle's pose.
  EXPECT_GE(radii.size(), 6u);
  EXPECT_LE(radii.size(), 8u);
  // Each for a pose that went out, and what the same code gives in one go
  // for that pose (the drives hold still, so every pose is the latest one).
  const model::PoseUncertainty<Scalar> whole = runtime->estimate_uncertainty(latest);
  ASSERT_GT(whole.r95_mm, 0.0f);
  for (const protocol::PoseUncertainty& u : radii) {
    EXPECT_EQ(poses.count(u.sequence), 1u) << int(u.sequence);
    EXPECT_NEAR(u.r95_position_mm, whole.r95_mm, 0.0006);
    EXPECT_NEAR(u.r95_orientation_deg, whole.r95_deg, 0.0006);
    EXPECT_NEAR(u.latent_share, whole.latent_share, 0.003);
    EXPECT_FALSE(u.extrapolating);
  }
  EXPECT_TRUE(runtime->has_uncertainty());
}

// While IK runs, the variance gets a slice every few cycles only, and IK
// the rest of those cycles' budget; radii keep coming, more slowly.
TEST_F(RuntimeUncertaintyTest, IkKeepsItsShareWhileTheVarianceWaits) {
  boot(image_with_variance(64));
  listen_to_poses();
  cycles(5);
  host_frames();
  const std::uint32_t beside_variance = runtime->ik_units_per_cycle();
  const model::Pose<double> target = runtime->latest_pose().pose.cast<double>();
  send_position_target(target.position_mm.x() + 2.0, target.position_mm.y(), target.position_mm.z(), 3);
  int radii = 0;
  int cycles_with_full_share = 0;
  int solving_cycles = 0;
  for (int cycle = 0; cycle < 200; ++cycle) {
    cycles(1);
    if (runtime->ik_running()) {
      ++solving_cycles;
      if (runtime->ik_units_per_cycle() == beside_variance + kUncertaintyUnitsPerCycle) ++cycles_with_full_share;
    }
    for (const hal::CanFrame& frame : host_frames()) {
      protocol::PoseUncertainty u;
      if (protocol::decode(frame, u) == protocol::DecodeStatus::ok) ++radii;
    }
  }
  EXPECT_GT(solving_cycles, 0);
  EXPECT_GE(cycles_with_full_share, solving_cycles * 3 / 4) << solving_cycles;
  EXPECT_GT(radii, 5);
  EXPECT_EQ(runtime->statistics().overruns, 0u);
}

// At the runtime's capacity, on a board whose budget does not hold the
// forward path, a slice and IK's smallest step together (the Cortex-M7's),
// the variance waits while IK runs; where it does (the host's), it gets its
// slice every few cycles as with any model.
TEST_F(RuntimeUncertaintyTest, AtTheCapacityTheVarianceNeverPushesACycleOverBudget) {
  constexpr std::uint32_t forward = kWorkCosts.cycle_overhead + kMaxTrainingPoints;
  constexpr bool fits = forward + kUncertaintyUnitsPerCycle + kMinIkUnitsPerCycle <= kCycleWorkUnits;
  boot(image_with_variance(16, 1.0, static_cast<int>(kMaxTrainingPoints)));
  ASSERT_EQ(runtime->state(), RuntimeState::run);
  listen_to_poses();
  cycles(3);
  const model::Pose<double> target = runtime->latest_pose().pose.cast<double>();
  send_position_target(target.position_mm.x() + 2.0, target.position_mm.y(), target.position_mm.z(), 4);
  const std::uint32_t alone = std::max(kCycleWorkUnits - forward, kMinIkUnitsPerCycle);
  int solving_cycles = 0;
  int beside_variance = 0;
  for (int cycle = 0; cycle < 60 && (cycle < 2 || runtime->ik_running()); ++cycle) {
    cycles(1);
    if (!runtime->ik_running()) continue;
    ++solving_cycles;
    if (runtime->ik_units_per_cycle() != alone) {
      ++beside_variance;
      // Never below IK's smallest step, never past the budget.
      EXPECT_GE(runtime->ik_units_per_cycle(), kMinIkUnitsPerCycle);
      EXPECT_LE(forward + kUncertaintyUnitsPerCycle + runtime->ik_units_per_cycle(), kCycleWorkUnits);
    }
  }
  EXPECT_GT(solving_cycles, 8);
  if (fits) {
    EXPECT_GT(beside_variance, 0);
  } else {
    EXPECT_EQ(beside_variance, 0);
  }
}

TEST_F(RuntimeUncertaintyTest, APoseBeyondTheFittedRangeIsFlaggedInThePoseAndStatus) {
  // A threshold of a thousandth of the prior: the held pose's variance,
  // above it, makes it extrapolate.
  boot(image_with_variance(16, 1e-3));
  listen_to_poses();
  cycles(30);
  ASSERT_TRUE(runtime->has_uncertainty());
  ASSERT_GT(runtime->latest_uncertainty().latent_share, 1e-3f);
  EXPECT_TRUE(runtime->extrapolating());
  bool pose_flag = false;
  bool status_flag = false;
  for (const hal::CanFrame& frame : host_frames()) {
    protocol::PosePositionZ z;
    if (protocol::decode(frame, z) == protocol::DecodeStatus::ok) pose_flag = pose_flag || z.extrapolating;
    protocol::Status status;
    if (protocol::decode(frame, status) == protocol::DecodeStatus::ok) status_flag = status_flag || status.extrapolating;
  }
  EXPECT_TRUE(pose_flag);
  EXPECT_TRUE(status_flag);
}

TEST_F(RuntimeUncertaintyTest, WithoutAVarianceBlockNoRadiiGoOut) {
  boot(test_support::small_image());
  listen_to_poses();
  EXPECT_EQ(runtime->ik_units_per_cycle(), kCycleWorkUnits - kWorkCosts.cycle_overhead - 5);
  cycles(20);
  for (const hal::CanFrame& frame : host_frames()) {
    protocol::PoseUncertainty u;
    EXPECT_NE(protocol::decode(frame, u), protocol::DecodeStatus::ok);
  }
  EXPECT_FALSE(runtime->has_uncertainty());
}

}  // namespace
}  // namespace cdcr::firmware
