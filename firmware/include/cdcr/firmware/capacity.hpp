#pragma once
// Every capacity of the runtime, fixed at compile time: storage is sized for
// these and nothing is allocated after init. Those the model and the HAL
// size their own storage by are theirs (model/limits.hpp,
// hal/can_bus.hpp), named here for the runtime; the rest are the runtime's.

#include <algorithm>
#include <cstdint>

#include "cdcr/hal/can_bus.hpp"
#include "cdcr/model/arch/selected.hpp"
#include "cdcr/model/gp_correction.hpp"
#include "cdcr/model/ik_solver.hpp"
#include "cdcr/model/work_costs.hpp"
#include "cdcr/model/limits.hpp"

namespace cdcr::firmware {

// Segments the runtime can drive (one cable feedback and one setpoint frame
// each; the CAN identifiers reserve room for 8).
using model::kMaxSegments;
static_assert(kMaxSegments <= 8, "the CAN identifiers reserve room for 8 segments");

// GP training points an image may hold; bounds the per-cycle correction cost.
using model::kMaxTrainingPoints;

// CiA 402 drives (hal::Drives' CANopen backend): one per cable, over at
// most this many buses, each with its own SYNC.
inline constexpr int kMaxDrives = model::kMaxCables;
inline constexpr int kMaxDriveBuses = 4;

// Frames the runtime drains from the bus per cycle; the rest wait for the
// next cycle, so a flood cannot stretch one cycle without bound.
inline constexpr int kMaxRxFramesPerCycle = 64;

// Acceptance filters a controller must offer the runtime (hal/can_bus.hpp).
using hal::kMaxCanFilters;

// The cycle budget, in work units (model/work_costs.hpp): one unit is one
// training point of a GP mean evaluation on the board's core, and every other
// kind of work is charged in the same units, measured on that core and stated
// in its architecture file (model/arch/<arch>). A cycle's forward path costs
// one unit per training point plus the fixed overhead; the IK solver gets
// what is left of kCycleWorkUnits, and at least kMinIkUnitsPerCycle, its
// costliest single step, so that a request advances in every cycle even at
// the full kMaxTrainingPoints. The qemu.cycle_budget_* tests hold the
// defaults to 80,000 instructions per cycle on the Cortex-M7 and 120,000 on
// the Cortex-M4F with the demo's model; tools/bench/README.md gives the
// figures at the full capacity. A board build may set its own budget with
// -DCDCR_CYCLE_WORK_UNITS=...
inline constexpr model::WorkCosts kWorkCosts = model::arch::Selected::kWorkCosts;
#ifdef CDCR_CYCLE_WORK_UNITS
inline constexpr std::uint32_t kCycleWorkUnits = CDCR_CYCLE_WORK_UNITS;
#else
inline constexpr std::uint32_t kCycleWorkUnits = kWorkCosts.cycle;
#endif
inline constexpr model::IkWorkCosts kIkWorkCosts = kWorkCosts.ik;
inline constexpr std::uint32_t kMinIkUnitsPerCycle =
    std::max({kIkWorkCosts.nominal_jacobian, kIkWorkCosts.nominal_step, kIkWorkCosts.outer_step, kWorkCosts.ik_finish,
              model::GpCorrection<float>::kChunkPoints * kWorkCosts.gradient_point});

// Work units a cycle spends on the predictive variance of the latest pose
// (model::GpUncertainty): an evaluation takes a few cycles (64 variance
// points cost 832 units: 5 cycles), and its radii go out when it ends.
inline constexpr std::uint32_t kUncertaintyUnitsPerCycle = 192;
// While an IK request runs, the variance gets its slice in every this many
// cycles only, so that IK keeps nearly its whole share (radii then come
// about every 40 cycles instead of every 5).
inline constexpr int kUncertaintyEveryCyclesWhileSolving = 8;
inline constexpr int kMaxVarianceRank = static_cast<int>(model::kMaxVarianceRank);

// Work units the cables' hysteresis takes from a cycle, with an image that
// has a hysteresis block (hysteresis_tracker.hpp), charged as part of the
// forward path: per cable and play operator, the update of its lag interval
// and the effective length; and, in a cycle that begins a pose variance while
// the state is unknown, the nominal Jacobian that widens the radii. Measured
// under QEMU by qemu.cycle_budget_hysteresis_<board> (16 cables x 2
// operators: a cable set's tracking at most 2,162 instructions on the M7
// and 2,210 on the M4F, the widening 2,951 and 4,818; the 142 units charged
// are 6,674 and 7,668 instructions there). The widening is charged
// in every cycle, though it runs only while the state is unknown.
inline constexpr std::uint32_t kHysteresisUnitsPerOperator = 1;
inline constexpr std::uint32_t kHysteresisWideningUnits = 110;

// Work units the payload's sag takes from a cycle, with an image that has a
// compliance block (model::sagged_bends in the forward path: kSagNewtonSteps
// passes of the chain with its twists and an 8 x 8 solve each), charged as
// part of the forward path. Measured under QEMU by
// qemu.cycle_budget_compliance_<board> on four segments: 20,924 instructions
// on the M7 (445 of its units of 47) and 25,167 on the M4F (449 of 56); the
// charge covers both. (The IK correction's inverse, 1,585 and 2,150 per
// evaluation, rides in the evaluation's own margin.)
inline constexpr std::uint32_t kComplianceUnits = 500;

// Bounds of one IK request: correction evaluations, nominal LM iterations
// and restarts after a stall (see model::IkSolverOptions), and the cycles
// it may span before it is reported unreachable. Over the full design
// range a stalled start needs room to restart: of 2,000 nominal pose
// targets from the straight start, 98.25 % converged with 400 iterations
// and 3 restarts, 99.45-99.5 % with 800 and 10, 99.55-99.75 % with 1,200
// and 10 over three seeds (tools/bench/ik_convergence_bench.cpp). Only
// requests that stall use the extra room; the cycle bound caps them.
inline constexpr int kMaxIkCorrections = 40;
inline constexpr int kMaxIkIterations = 1200;
inline constexpr int kMaxIkRestarts = 10;
inline constexpr int kMaxIkCycles = 250;
// The start of a request with no setpoints and no pose yet (and of the
// retry of a refused solution): every segment at this bend, alpha 0. The
// straight robot is singular (the alpha columns of the Jacobian vanish).
inline constexpr float kIkStraightStartThetaRad = 0.1f;

// IK_REPORT with outcome in_progress goes out every this many cycles while
// a request runs.
inline constexpr int kIkProgressEveryCycles = 10;

// Cycles without a fresh, valid cable frame from every segment before the
// runtime declares its input stale.
inline constexpr int kStaleInputCycles = 10;

// Console lines are formatted into a fixed buffer.
inline constexpr int kConsoleLineBytes = 96;

}  // namespace cdcr::firmware

namespace cdcr::firmware {

// The most of a CAN bus's time a configuration may plan to use, at its
// worst case (protocol/bus_budget.hpp): above it, arbitration delays for the
// lowest-priority frames grow without a useful bound and a burst of the
// host's own frames (an update, a payload) has no room.
inline constexpr double kMaxBusLoad = 0.70;

// STATUS and STATS go out every this many cycles: at 1 kHz a heartbeat per
// cycle would take a fifth of a 1 Mbit/s bus on its own.
inline constexpr int kStatusEveryCycles = 10;

}  // namespace cdcr::firmware

namespace cdcr::firmware {

// A target counts as reached when the solver's residual is within these,
// even if its own (float rounding-level) tolerances were not met: a tenth of
// the drives' cable resolution is far below what the robot can repeat.
inline constexpr float kIkAcceptedPositionErrorMm = 0.05f;
inline constexpr float kIkAcceptedOrientationErrorRad = 1e-3f;

}  // namespace cdcr::firmware

namespace cdcr::firmware {

// Model updates over CAN (model_update.hpp). Blocks the runtime holds in RAM
// between their arrival and their program: the window it grants the host.
inline constexpr int kUpdateWindowBlocks = 8;
// An acknowledgement goes out after this many blocks reached the flash (and
// whenever the runtime has caught up with what it received).
inline constexpr int kUpdateAckEveryBlocks = 4;
// Bytes of the new image hashed per cycle while it is verified, at most
// (1 KiB of SHA-256 and scan is about 64,000 instructions on a Cortex-M7,
// four fifths of its cycle's budget). The update's
// work is charged in work units and comes out of IK's share of the cycle,
// which keeps at least kMinIkUnitsPerCycle while a request runs; the slice
// shrinks (in steps of 64 bytes) to what is left. Charges, measured under
// QEMU by qemu.update_budget_<board> (instructions per unit: the mean
// point's, 47 on the M7 and 54 on the M4F): each update frame received, a
// step's fixed work (a flash operation started or polled, a report), and 64
// bytes hashed (SHA-256 and model::ImageScan).
inline constexpr std::uint32_t kUpdateHashBytesPerCycle = 1024;
inline constexpr std::uint32_t kUpdateFrameUnits = 3;
inline constexpr std::uint32_t kUpdateStepUnits = 100;
inline constexpr std::uint32_t kUpdateHashUnitsPer64Bytes = 90;
// When what IK's share leaves above its floor cannot hash one 64-byte piece
// (a model near the cycle's capacity with targets streaming), every this
// many cycles the update's verification gets IK's whole share and IK waits
// that cycle: a stream of targets cannot hold a verification up for ever.
inline constexpr int kUpdateTurnEveryCyclesWhileSolving = 8;
// A transfer without a valid frame for this many cycles (a minute at 1 kHz)
// is dropped with reason timeout; the host may resume it with START.
inline constexpr std::uint32_t kUpdateTimeoutCycles = 60'000;
// A new image's segments may differ from the running model's geometry by
// this fraction of their length and radius (a recalibration), no more.
inline constexpr float kUpdateGeometryTolerance = 0.05f;

}  // namespace cdcr::firmware
