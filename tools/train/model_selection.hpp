#pragma once
// Which GP `cdcr train` ships, and with how many points: the largest model
// the board can run. A model's points cost flash (the image) and time (the
// forward cycle sums over them), and the runtime holds a fixed number. The
// exact GP on every row is the best model while its rows fit; beyond that,
// a sparse GP whose M inducing points fit.

#include <cstdint>
#include <string>

#include "cdcr/model/limits.hpp"
#include "cdcr/model/work_costs.hpp"

namespace cdcr::training {

enum class ModelChoice { automatic, exact, sparse };
enum class ModelKind { exact, sparse };

const char* to_string(ModelKind kind);

struct BoardLimits {
  std::uint32_t flash_budget_bytes = 96 * 1024;
  // The Cortex-M7's forward cycle, in instructions.
  std::uint32_t forward_cycle_instructions = 60'000;
  model::ForwardCycleInstructions forward_cycle = model::kCortexM7ForwardCycle;
  std::uint32_t capacity_points = model::kMaxTrainingPoints;
  // Points of the variance factor the image carries beside the model's own
  // (its block counts against the flash budget).
  std::uint32_t variance_rank = 0;
};

struct ModelSelection {
  ModelKind kind = ModelKind::exact;
  int points = 0;         // N for the exact GP, M for the sparse one
  int fitted_rows = 0;
  int largest_points = 0;  // what the board allows
  std::uint32_t image_bytes = 0;
  std::uint32_t forward_cycle_instructions = 0;
  std::string reason;     // one sentence for the user
};

// rows: the rows the shipped model is fitted on. requested_points: M for a
// sparse model (0: the largest that fits). Throws std::invalid_argument with
// a one-line reason when no model of the requested kind fits.
ModelSelection select_model(int rows, int input_dims, int segments, ModelChoice choice, int requested_points,
                            const BoardLimits& limits = {});

}  // namespace cdcr::training
