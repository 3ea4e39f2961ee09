// What `cdcr train` ships: the exact GP while one point per row fits the
// board, else a sparse GP with the most inducing points that do. Each limit
// (the runtime's capacity, the flash budget, the Cortex-M7 forward cycle) is
// checked against the image layout and the cycle figures directly.
#include <gtest/gtest.h>

#include "cdcr/model/flash_image.hpp"
#include "model_selection.hpp"

namespace {

using cdcr::training::BoardLimits;
using cdcr::training::ModelChoice;
using cdcr::training::ModelKind;
using cdcr::training::select_model;

constexpr int kSegments = 4;
constexpr int kInputs = 8;

std::uint32_t image_bytes(int points) {
  return cdcr::model::image_layout(static_cast<std::uint32_t>(points), kInputs, kSegments).total_size;
}

TEST(ModelSelection, ExactWhileEveryRowFits) {
  const auto s = select_model(700, kInputs, kSegments, ModelChoice::automatic, 0);
  EXPECT_EQ(s.kind, ModelKind::exact);
  EXPECT_EQ(s.points, 700);
  EXPECT_EQ(s.fitted_rows, 700);
  EXPECT_EQ(s.image_bytes, image_bytes(700));
  EXPECT_EQ(s.forward_cycle_instructions, cdcr::model::kCortexM7ForwardCycle.for_points(700, false));
  const auto at_capacity = select_model(1024, kInputs, kSegments, ModelChoice::automatic, 0);
  EXPECT_EQ(at_capacity.kind, ModelKind::exact);
}

TEST(ModelSelection, SparseAtTheRuntimesCapacityBeyondIt) {
  const auto s = select_model(4000, kInputs, kSegments, ModelChoice::automatic, 0);
  EXPECT_EQ(s.kind, ModelKind::sparse);
  EXPECT_EQ(s.points, 1024);
  EXPECT_EQ(s.fitted_rows, 4000);
  EXPECT_LE(s.image_bytes, 96u * 1024u);
  EXPECT_LE(s.forward_cycle_instructions, 60'000u);
  EXPECT_NE(s.reason.find("capacity"), std::string::npos) << s.reason;
}

TEST(ModelSelection, TheFlashBudgetBoundsThePoints) {
  BoardLimits limits;
  limits.flash_budget_bytes = 20'000;
  const auto s = select_model(4000, kInputs, kSegments, ModelChoice::automatic, 0, limits);
  EXPECT_EQ(s.kind, ModelKind::sparse);
  EXPECT_LE(image_bytes(s.points), 20'000u);
  EXPECT_GT(image_bytes(s.points + 1), 20'000u);
  EXPECT_NE(s.reason.find("flash budget"), std::string::npos) << s.reason;
  // Fewer rows than that: exact.
  EXPECT_EQ(select_model(s.points, kInputs, kSegments, ModelChoice::automatic, 0, limits).kind, ModelKind::exact);
  EXPECT_EQ(select_model(s.points + 1, kInputs, kSegments, ModelChoice::automatic, 0, limits).kind,
            ModelKind::sparse);
}

TEST(ModelSelection, TheForwardCycleBoundsThePoints) {
  BoardLimits limits;
  limits.forward_cycle_instructions = 30'000;
  const auto s = select_model(4000, kInputs, kSegments, ModelChoice::automatic, 0, limits);
  const auto& cycle = cdcr::model::kCortexM7ForwardCycle;
  EXPECT_LE(cycle.fixed + cycle.per_point * static_cast<std::uint32_t>(s.points), 30'000u);
  EXPECT_GT(cycle.fixed + cycle.per_point * static_cast<std::uint32_t>(s.points + 1), 30'000u);
  EXPECT_NE(s.reason.find("forward cycle"), std::string::npos) << s.reason;
}

TEST(ModelSelection, RequestsBeyondTheBoardAreRefused) {
  EXPECT_THROW(select_model(2000, kInputs, kSegments, ModelChoice::exact, 0), std::invalid_argument);
  EXPECT_THROW(select_model(4000, kInputs, kSegments, ModelChoice::sparse, 1025), std::invalid_argument);
  EXPECT_THROW(select_model(300, kInputs, kSegments, ModelChoice::sparse, 301), std::invalid_argument);
  BoardLimits tiny;
  tiny.flash_budget_bytes = 100;
  EXPECT_THROW(select_model(10, kInputs, kSegments, ModelChoice::automatic, 0, tiny), std::invalid_argument);
  const auto asked = select_model(300, kInputs, kSegments, ModelChoice::sparse, 40);
  EXPECT_EQ(asked.kind, ModelKind::sparse);
  EXPECT_EQ(asked.points, 40);
}

}  // namespace
