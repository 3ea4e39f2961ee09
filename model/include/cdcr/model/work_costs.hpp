#pragma once
// The cost model of the fixed-rate cycle. Work is counted in units: one unit
// is one training point of a GP mean evaluation on the core at hand. Every
// other kind of work is charged as a whole number of such units, measured on
// that core (each architecture file, model/arch/<arch>, states its own), so
// a budget in units bounds a cycle's instructions.

#include <cstdint>

namespace cdcr::model {

// What the resumable IK solver charges for each kind of step. A nominal LM
// iteration is two steps: the linearised model's Jacobian at the current
// point, then the damped step and the evaluation of where it lands (a
// rejected step repeats only the second).
struct IkWorkCosts {
  std::uint32_t nominal_jacobian = 80;
  std::uint32_t nominal_step = 80;
  std::uint32_t outer_step = 60;
};

struct WorkCosts {
  // A training point of the mean together with its gradient.
  std::uint32_t gradient_point = 3;
  IkWorkCosts ik{};
  // The end of an IK request, or a streamed target's best point so far:
  // the cable lengths of the joints, the setpoint frames and the report.
  std::uint32_t ik_finish = 150;
  // A cycle's work beyond the GP sum and the IK slice: the cables' joints,
  // the nominal forward kinematics and the exponential, the frames it sends,
  // a target's start and an in-progress report.
  std::uint32_t cycle_overhead = 150;
  // The default budget of one cycle, overhead and GP sum included: what the
  // boards this architecture targets can do in one period.
  std::uint32_t cycle = 2000;
  // A training point of a model with extra inputs (the payload), whose odd
  // input count runs in the loop that reads the count at run time: the
  // mean's point, and the point with its gradient.
  std::uint32_t run_time_loop_point = 3;
  std::uint32_t run_time_loop_gradient_point = 10;
  // A drive behind a hal::Drives backend, every cycle (CiA 402: its TPDO
  // taken, its heartbeat watched, its setpoint converted, its RPDO built
  // and queued, its share of the SYNC).
  std::uint32_t drive = 4;
};

// A forward cycle's instructions on a board as a function of the model's
// points: the GP mean's loop per point, the rest of the cycle (cable
// frames, joints, nominal kinematics, the exponential, the pose frames), and
// the slice of the predictive variance a cycle runs when the image carries
// one. qemu.cycle_bench_<board> fails when a measured forward cycle exceeds
// it; the trainer sizes models with it.
//
// A model with extra inputs (the payload) has an odd input count, which
// the mean's unrolled and hand-written loops do not cover: its points run
// in the loop that reads the count at run time, charged at
// per_point_run_time_loop.
struct ForwardCycleInstructions {
  std::uint32_t fixed;
  std::uint32_t per_point;
  std::uint32_t variance_slice;
  std::uint32_t per_point_run_time_loop;
  // The payload's sag (payload_compliance.hpp's sagged_bends), in a cycle
  // of a model with a compliance block: the trainer sizes such a model
  // within the budget less this.
  std::uint32_t compliance_sag;

  constexpr std::uint32_t point_cost(int extra_inputs) const {
    return extra_inputs > 0 ? per_point_run_time_loop : per_point;
  }
  constexpr std::uint32_t for_points(std::uint32_t points, bool with_variance, int extra_inputs = 0) const {
    return fixed + point_cost(extra_inputs) * points + (with_variance ? variance_slice : 0);
  }
  // The most points whose forward cycle fits `budget` (0 if none does).
  constexpr std::uint32_t points_within(std::uint32_t budget, bool with_variance, int extra_inputs = 0) const {
    const std::uint32_t base = fixed + (with_variance ? variance_slice : 0);
    return budget > base ? (budget - base) / point_cost(extra_inputs) : 0;
  }
};

// Measured with the 700-point demo model: without a variance block at most
// 37,796 instructions on the M7 and 50,611 on the M4F (at 1,024 points the
// M7 measured 52,721); with its 64-point variance block, whose slice
// (firmware::kUncertaintyUnitsPerCycle) adds about 10,100 on the M7 and
// 10,900 on the M4F, at most 47,872 and 61,515. Rounded up. A payload
// model's point (9 inputs, the run-time loop) measured 100 instructions on
// the M7 (473 points, forward cycles up to 61,744 with the variance); the
// M4F's is charged at twice its unrolled point until measured.
// The sag of a four-segment robot (kSagNewtonSteps Newton steps) measured
// by qemu.cycle_budget_compliance_<board>: 20,924 instructions on the M7,
// 25,167 on the M4F (27,631 before the firmware's out-of-line copy); rounded
// up. The fixed part since CAN FD's 64-byte frames (each frame of a
// cycle built, queued and taken at 72 bytes): 49,272 instructions at most
// on the M7 with the variance, 570 above the 5,500 charged before; 62,314
// on the M4F, 410 above its 13,000.
inline constexpr ForwardCycleInstructions kCortexM7ForwardCycle{6'200, 47, 10'300, 101, 21'000};
inline constexpr ForwardCycleInstructions kCortexM4fForwardCycle{13'500, 54, 11'100, 108, 28'000};

}  // namespace cdcr::model
