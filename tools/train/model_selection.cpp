#include "model_selection.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

#include "cdcr/model/flash_image.hpp"

namespace cdcr::training {

const char* to_string(ModelKind kind) { return kind == ModelKind::sparse ? "sparse" : "exact"; }

namespace {

std::uint32_t image_bytes(int points, int input_dims, int segments, std::uint32_t variance_rank) {
  return model::image_layout(static_cast<std::uint32_t>(points), static_cast<std::uint32_t>(input_dims),
                             static_cast<std::uint32_t>(segments), model::kImageVersionMajor, variance_rank,
                             static_cast<std::uint32_t>(input_dims - 2 * segments))
      .total_size;
}

// The most points whose image fits the budget: the size grows with them.
int points_within_flash(int input_dims, int segments, std::uint32_t variance_rank, std::uint32_t budget,
                        int at_most) {
  int low = 0;
  int high = at_most;
  while (low < high) {
    const int middle = (low + high + 1) / 2;
    if (image_bytes(middle, input_dims, segments, variance_rank) <= budget) {
      low = middle;
    } else {
      high = middle - 1;
    }
  }
  return low;
}

}  // namespace

ModelSelection select_model(int rows, int input_dims, int segments, ModelChoice choice, int requested_points,
                            const BoardLimits& limits) {
  if (rows < 1) throw std::invalid_argument("no rows to fit a model on");
  if (requested_points < 0) throw std::invalid_argument(fmt::format("--inducing must not be negative (got {})", requested_points));
  const int capacity = static_cast<int>(limits.capacity_points);
  const int by_flash =
      points_within_flash(input_dims, segments, limits.variance_rank, limits.flash_budget_bytes, capacity);
  const bool with_variance = limits.variance_rank > 0;
  const int extra_inputs = input_dims - 2 * segments;
  const int by_cycle = static_cast<int>(
      limits.forward_cycle.points_within(limits.forward_cycle_instructions, with_variance, extra_inputs));
  const int largest = std::min({capacity, by_flash, by_cycle});
  // The tightest of the three limits, in words.
  std::string limit;
  if (largest == capacity) {
    limit = fmt::format("the runtime's capacity of {} points", capacity);
  } else if (largest == by_flash) {
    limit = limits.variance_rank > 0
                ? fmt::format("the flash budget of {} bytes beside a variance factor of {} points ({} points)",
                              limits.flash_budget_bytes, limits.variance_rank, by_flash)
                : fmt::format("the flash budget of {} bytes ({} points)", limits.flash_budget_bytes, by_flash);
  } else {
    limit = fmt::format("the Cortex-M7 forward cycle of {} instructions ({} points)",
                        limits.forward_cycle_instructions, by_cycle);
  }
  if (largest < 1) throw std::invalid_argument(fmt::format("no model fits {}", limit));

  ModelSelection s;
  s.fitted_rows = rows;
  s.largest_points = largest;
  if (choice == ModelChoice::exact || (choice == ModelChoice::automatic && rows <= largest)) {
    if (rows > largest) {
      throw std::invalid_argument(
          fmt::format("an exact GP on {} rows has {} points, more than {}; use --model sparse or auto", rows, rows,
                      limit));
    }
    s.kind = ModelKind::exact;
    s.points = rows;
    s.reason = choice == ModelChoice::exact
                   ? fmt::format("exact GP as requested: its {} points fit {}", rows, limit)
                   : fmt::format("exact GP: its {} points (one per row) fit {}", rows, limit);
  } else {
    const int points = requested_points > 0 ? requested_points : std::min(largest, rows);
    if (points > largest) {
      throw std::invalid_argument(fmt::format("--inducing {} is more than {}", points, limit));
    }
    if (points > rows) {
      throw std::invalid_argument(fmt::format("--inducing {} is more than the {} rows", points, rows));
    }
    s.kind = ModelKind::sparse;
    s.points = points;
    if (choice == ModelChoice::sparse) {
      s.reason = requested_points > 0 ? fmt::format("sparse GP as requested, {} inducing points", points)
                                      : fmt::format("sparse GP as requested, {} inducing points: {}", points, limit);
    } else {
      s.reason = fmt::format("sparse GP, {} inducing points: an exact GP's {} points exceed {}", points, rows, limit);
    }
  }
  s.image_bytes = image_bytes(s.points, input_dims, segments, limits.variance_rank);
  s.forward_cycle_instructions =
      limits.forward_cycle.for_points(static_cast<std::uint32_t>(s.points), with_variance, extra_inputs);
  return s;
}

}  // namespace cdcr::training
