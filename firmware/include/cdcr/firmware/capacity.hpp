#pragma once
// Every capacity of the runtime, fixed at compile time: storage is sized for
// these and nothing is allocated after init. A board build may lower them.

#include <cstdint>

#include "cdcr/model/limits.hpp"

namespace cdcr::firmware {

// Segments the runtime can drive (one cable feedback and one setpoint frame
// each; the CAN identifiers reserve room for 8).
inline constexpr int kMaxSegments = 8;
static_assert(kMaxSegments <= model::kMaxSegments, "the model's storage must hold every segment");

// GP training points an image may hold; bounds the per-cycle correction cost.
inline constexpr std::uint32_t kMaxTrainingPoints = 1024;
static_assert(kMaxTrainingPoints <= model::kMaxTrainingPoints, "the model's capacity must cover the runtime's");

// Frames the runtime drains from the bus per cycle; the rest wait for the
// next cycle, so a flood cannot stretch one cycle without bound.
inline constexpr int kMaxRxFramesPerCycle = 64;

// Depth of each receive queue of the simulated bus (a board's controller
// FIFO plays this role).
inline constexpr int kRxQueueDepth = 128;

// Acceptance filters a controller must offer the runtime.
inline constexpr int kMaxCanFilters = 4;

// Levenberg-Marquardt iterations one IK request may take; bounds the cycle
// in which a target arrives. Each iteration, accepted or not, costs one
// compensated model evaluation (tip pose, Jacobian, GP mean and gradient over
// every training point), plus one for the start: a target cycle costs at most
// kMaxIkIterations + 1 of them on top of the forward path.
// cdcr-bench-runtime measures that worst case.
inline constexpr int kMaxIkIterations = 50;

// Cycles without a fresh, valid cable frame from every segment before the
// runtime declares its input stale.
inline constexpr int kStaleInputCycles = 10;

// Console lines are formatted into a fixed buffer.
inline constexpr int kConsoleLineBytes = 96;

}  // namespace cdcr::firmware

namespace cdcr::firmware {

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
