// The cycle's shares, decided in one place: IK gets what the forward path
// and a variance slice leave, the variance waits while IK runs, a model
// update takes from IK's share above its floor, and a starved verification
// gets its turn.
#include <gtest/gtest.h>

#include "cdcr/firmware/cycle_scheduler.hpp"

namespace cdcr::firmware {
namespace {

constexpr std::uint32_t kMeanUnits = 400;  // a small model: everything fits

ModelCosts compensated_model(std::uint32_t mean_units) {
  return ModelCosts{true, true, mean_units, 0};
}

TEST(CycleScheduler, IkGetsWhatTheForwardPathAndTheVarianceLeave) {
  CycleScheduler scheduler;
  scheduler.configure(compensated_model(kMeanUnits));
  const std::uint32_t alone = kCycleWorkUnits - kWorkCosts.cycle_overhead - kMeanUnits;
  EXPECT_EQ(scheduler.ik_units(), alone - kUncertaintyUnitsPerCycle);  // after init: the smaller share

  CyclePlan plan = scheduler.plan(1, /*variance_pending=*/true, /*ik_running=*/false, false);
  EXPECT_TRUE(plan.variance_slice);
  EXPECT_EQ(scheduler.ik_units(), alone - kUncertaintyUnitsPerCycle);
  plan = scheduler.plan(2, false, false, false);
  EXPECT_FALSE(plan.variance_slice);
  EXPECT_EQ(scheduler.ik_units(), alone);
}

TEST(CycleScheduler, NominalModelCostsTheOverheadOnly) {
  CycleScheduler scheduler;
  scheduler.configure(ModelCosts{false, true, kMeanUnits, 0});
  scheduler.plan(1, true, false, false);
  EXPECT_EQ(scheduler.ik_units(), kCycleWorkUnits - kWorkCosts.cycle_overhead);
}

// The payload's sag runs in the forward path of a compensated model with a
// compliance block: its units come out of IK's share; a nominal model runs
// no sag.
TEST(CycleScheduler, TheSagIsChargedToTheForwardPath) {
  CycleScheduler scheduler;
  ModelCosts costs = compensated_model(kMeanUnits);
  costs.compliance_units = kComplianceUnits;
  scheduler.configure(costs);
  scheduler.plan(1, false, false, false);
  EXPECT_EQ(scheduler.ik_units(), kCycleWorkUnits - kWorkCosts.cycle_overhead - kMeanUnits - kComplianceUnits);
  costs.compensated = false;
  scheduler.configure(costs);
  scheduler.plan(1, false, false, false);
  EXPECT_EQ(scheduler.ik_units(), kCycleWorkUnits - kWorkCosts.cycle_overhead);
}

TEST(CycleScheduler, WhileIkRunsTheVarianceGetsEveryFewCyclesOnly) {
  CycleScheduler scheduler;
  scheduler.configure(compensated_model(kMeanUnits));
  int slices = 0;
  for (std::uint32_t cycle = 1; cycle <= 8 * kUncertaintyEveryCyclesWhileSolving; ++cycle) {
    const CyclePlan plan = scheduler.plan(cycle, true, true, false);
    if (plan.variance_slice) {
      ++slices;
      EXPECT_EQ(cycle % kUncertaintyEveryCyclesWhileSolving, 0u);
    }
  }
  EXPECT_EQ(slices, 8);
}

TEST(CycleScheduler, ALargeModelKeepsIkAtItsFloorAndTheVarianceWaits) {
  CycleScheduler scheduler;
  scheduler.configure(compensated_model(kCycleWorkUnits));
  const CyclePlan plan = scheduler.plan(kUncertaintyEveryCyclesWhileSolving, true, true, false);
  EXPECT_FALSE(plan.variance_slice);
  EXPECT_EQ(scheduler.ik_units(), kMinIkUnitsPerCycle);
  // A payload model's gradient block is IK's smallest step when it is larger.
  scheduler.configure(ModelCosts{true, true, kCycleWorkUnits, kMinIkUnitsPerCycle + 7});
  scheduler.plan(1, false, true, false);
  EXPECT_EQ(scheduler.ik_units(), kMinIkUnitsPerCycle + 7);
}

TEST(CycleScheduler, TheUpdateTakesFromIkAboveItsFloor) {
  CycleScheduler scheduler;
  scheduler.configure(compensated_model(kMeanUnits));
  CyclePlan plan = scheduler.plan(1, false, true, false);
  const std::uint32_t share = scheduler.ik_units();
  EXPECT_EQ(plan.update_offer, share - kMinIkUnitsPerCycle);
  EXPECT_FALSE(plan.update_turn);
  scheduler.charge_update(100);
  EXPECT_EQ(scheduler.ik_units(), share - 100);
  plan = scheduler.plan(2, false, true, false);
  scheduler.charge_update(plan.update_offer + 50);  // an update frame's units beyond the offer
  EXPECT_EQ(scheduler.ik_units(), kMinIkUnitsPerCycle);
  // Without a request the update may have the whole share.
  plan = scheduler.plan(3, false, false, false);
  EXPECT_EQ(plan.update_offer, scheduler.ik_units());
}

TEST(CycleScheduler, AStarvedVerificationGetsIksWholeShareEveryFewCycles) {
  CycleScheduler scheduler;
  scheduler.configure(compensated_model(kCycleWorkUnits));  // IK at its floor: nothing above it
  int turns = 0;
  for (std::uint32_t cycle = 1; cycle <= 4 * kUpdateTurnEveryCyclesWhileSolving; ++cycle) {
    const CyclePlan plan = scheduler.plan(cycle, false, true, /*update_verifying=*/true);
    if (plan.update_turn) {
      ++turns;
      EXPECT_EQ(cycle % kUpdateTurnEveryCyclesWhileSolving, 0u);
      EXPECT_EQ(plan.update_offer, kMinIkUnitsPerCycle);
      scheduler.charge_update(plan.update_offer);
      EXPECT_EQ(scheduler.ik_units(), 0u);
    } else {
      EXPECT_EQ(plan.update_offer, 0u);
    }
  }
  EXPECT_EQ(turns, 4);
  // No turn while the share above the floor pays for a step and a piece.
  scheduler.configure(compensated_model(kMeanUnits));
  EXPECT_FALSE(scheduler.plan(kUpdateTurnEveryCyclesWhileSolving, false, true, true).update_turn);
}

}  // namespace
}  // namespace cdcr::firmware
