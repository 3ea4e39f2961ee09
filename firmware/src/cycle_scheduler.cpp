#include "cdcr/firmware/cycle_scheduler.hpp"

namespace cdcr::firmware {

void CycleScheduler::configure(const ModelCosts& costs) {
  const std::uint32_t forward_units =
      kWorkCosts.cycle_overhead + (costs.compensated ? costs.mean_units + costs.compliance_units : 0) +
      costs.hysteresis_units + costs.drives_units;
  // A payload model's points cost more units each (work_costs.hpp), and
  // IK's smallest step may then be a block of its gradient.
  const std::uint32_t min_ik_units =
      costs.compensated && costs.gradient_slice > kMinIkUnitsPerCycle ? costs.gradient_slice : kMinIkUnitsPerCycle;
  const auto ik_share = [min_ik_units](std::uint32_t used) {
    return used + min_ik_units < kCycleWorkUnits ? kCycleWorkUnits - used : min_ik_units;
  };
  const bool with_variance = costs.compensated && costs.with_variance;
  ik_units_alone_ = ik_share(forward_units);
  ik_units_beside_variance_ = ik_share(forward_units + (with_variance ? kUncertaintyUnitsPerCycle : 0));
  ik_units_ = ik_units_beside_variance_;
  // A large model leaves no room for a slice beside IK's smallest step:
  // then the variance waits while a target is solved.
  variance_beside_ik_ = forward_units + kUncertaintyUnitsPerCycle + min_ik_units <= kCycleWorkUnits;
}

CyclePlan CycleScheduler::plan(std::uint32_t cycle, bool variance_pending, bool ik_running, bool update_verifying) {
  CyclePlan plan;
  // While a target is solved, the variance gets a slice every few cycles
  // only: IK's latency is what a user waits on.
  plan.variance_slice =
      variance_pending && (!ik_running || (variance_beside_ik_ && cycle % kUncertaintyEveryCyclesWhileSolving == 0));
  ik_units_ = plan.variance_slice ? ik_units_beside_variance_ : ik_units_alone_;
  // The update's work comes out of IK's share, short of IK's smallest step.
  ik_floor_ = ik_running ? kMinIkUnitsPerCycle : 0;
  plan.update_turn = ik_running && update_verifying &&
                     ik_units_ < ik_floor_ + kUpdateStepUnits + kUpdateHashUnitsPer64Bytes &&
                     cycle % kUpdateTurnEveryCyclesWhileSolving == 0;
  if (plan.update_turn) ik_floor_ = 0;
  plan.update_offer = ik_units_ > ik_floor_ ? ik_units_ - ik_floor_ : 0;
  return plan;
}

void CycleScheduler::charge_update(std::uint32_t units) {
  ik_units_ = ik_units_ > units + ik_floor_ ? ik_units_ - units : ik_floor_;
}

}  // namespace cdcr::firmware
