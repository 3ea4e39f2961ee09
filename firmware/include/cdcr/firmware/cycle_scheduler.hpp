#pragma once
// Who gets how much of a cycle, decided in one place from the capacities in
// capacity.hpp. A cycle's kCycleWorkUnits go first to the forward path (the
// fixed overhead and one mean point's units per training point), then to a
// slice of the pose variance when one is due, and the rest to IK, never less
// than its smallest step while a request runs. A model update's work comes
// out of IK's share above that floor; a verification that gets nothing from
// it takes IK's whole share every kUpdateTurnEveryCyclesWhileSolving cycles.

#include <cstdint>

#include "cdcr/firmware/capacity.hpp"

namespace cdcr::firmware {

// What the bound model costs a cycle (work units, model/work_costs.hpp).
struct ModelCosts {
  bool compensated = false;          // a GP correction is evaluated each cycle
  bool with_variance = false;        // the image has a variance block
  std::uint32_t mean_units = 0;      // training points x units per point
  std::uint32_t gradient_slice = 0;  // the smallest block of the GP gradient
  std::uint32_t hysteresis_units = 0;  // the cables' hysteresis (hysteresis_units(); 0 without a block)
  std::uint32_t compliance_units = 0;  // the payload's sag (kComplianceUnits; 0 without a block)
  std::uint32_t drives_units = 0;      // a hal::Drives backend's drives (kWorkCosts.drive each; 0 without one)
};

// The cycle's decisions, in the order the runtime acts on them.
struct CyclePlan {
  bool variance_slice = false;   // continue the pose variance this cycle
  std::uint32_t update_offer = 0;  // units the model update may spend
  bool update_turn = false;      // the update has IK's share: no IK slice
};

class CycleScheduler {
 public:
  // At init, for the model just bound; IK's share is then the smaller one,
  // beside a variance slice.
  void configure(const ModelCosts& costs);

  // This cycle's plan: `variance_pending` a variance evaluation is in
  // progress, `ik_running` a request, `update_verifying` an image is hashed.
  CyclePlan plan(std::uint32_t cycle, bool variance_pending, bool ik_running, bool update_verifying);
  // What the update spent of its offer: IK gets the rest of its share.
  void charge_update(std::uint32_t units);

  // IK's share of the current cycle (of the last one, between cycles).
  std::uint32_t ik_units() const { return ik_units_; }

 private:
  std::uint32_t ik_units_ = kMinIkUnitsPerCycle;
  std::uint32_t ik_units_alone_ = kMinIkUnitsPerCycle;            // in a cycle without a variance slice
  std::uint32_t ik_units_beside_variance_ = kMinIkUnitsPerCycle;  // in a cycle with one
  std::uint32_t ik_floor_ = 0;  // IK's share the update leaves alone this cycle
  bool variance_beside_ik_ = false;  // a slice fits beside IK's smallest step
};

}  // namespace cdcr::firmware
