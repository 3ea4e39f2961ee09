// Where each cable last moved, as GP inputs (train/history_inputs.hpp):
// offered by evidence on a sequence made here (not by the simulator), kept
// where the tip depends on the direction of a cable's last move in a way no
// lag of its length describes, and left out where it does not; the board's
// float32 path with the tracker's history gives the trainer's poses.
#include <cmath>
#include <numeric>
#include <vector>

#include <gtest/gtest.h>

#include "hysteresis_sequence.hpp"
#include "pipeline/train_and_export.hpp"
#include "train/history_inputs.hpp"

namespace cdcr::training {
namespace {

std::vector<int> rows_from(int first, int count) {
  std::vector<int> rows(static_cast<std::size_t>(count));
  std::iota(rows.begin(), rows.end(), first);
  return rows;
}

TrainingOptions quick_options() {
  TrainingOptions options;
  options.search.restarts = 1;
  options.variance_rank = 16;
  return options;
}

TEST(HistoryOperator, IsAppendedWithWeightZeroAndItsHomingLag) {
  const auto geometry = test::two_segment_geometry();
  const auto known = test::known_hysteresis(geometry);
  const model::HysteresisModel<double> m = with_history_operator(known, 0.2, geometry);
  ASSERT_EQ(m.operators, 2);
  for (int c = 0; c < m.cables; ++c) {
    EXPECT_EQ(m.widths_mm[c][0], known.widths_mm[c][0]);
    EXPECT_EQ(m.weights[c][0], known.weights[c][0]);
    EXPECT_EQ(m.homing_lag_mm[c][0], known.homing_lag_mm[c][0]);
    EXPECT_EQ(m.widths_mm[c][1], 0.2);
    EXPECT_EQ(m.weights[c][1], 0.0);
    // The way home is 4.7 mm on this robot: each cable ends at a stop.
    EXPECT_DOUBLE_EQ(std::abs(m.homing_lag_mm[c][1]), 0.2);
  }
  EXPECT_EQ(model::check_hysteresis(m, 8), model::HysteresisCheck::ok);
  // An empty model becomes the history operator alone.
  const model::HysteresisModel<double> alone = with_history_operator({}, 0.05, geometry);
  EXPECT_EQ(alone.cables, 8);
  EXPECT_EQ(alone.operators, 1);
  model::HysteresisModel<double> full = known;
  full.operators = model::kMaxHysteresisOperators;
  EXPECT_THROW(with_history_operator(full, 0.2, geometry), std::invalid_argument);
  EXPECT_THROW(with_history_operator(known, 0.0, geometry), std::invalid_argument);
}

// Cable 1's last move shifts the tip 1 mm along z (20 times the noise): the
// history is chosen and takes a third off the held-out error of the model
// without it at least (1.14 -> 0.67 mm seen; the same robot without the
// effect, 0.40 mm), and the image's float32 path (the history run in
// float32 from the block, as the board's tracker keeps it) gives the same
// poses.
TEST(HistoryInputs, AreKeptWhereTheTipDependsOnTheLastMove) {
  const auto geometry = test::two_segment_geometry();
  const test::SyntheticSequence s = test::synthetic_sequence(geometry, {}, {400}, 21, 0.05, 1.0);
  const std::vector<int> train = rows_from(0, 300), validation = rows_from(300, 100);
  const TrainingOptions options = quick_options();
  const HistoryChoice choice = choose_history_inputs(s.data, train, {}, geometry, options);
  ASSERT_TRUE(choice.searched);
  ASSERT_TRUE(choice.chosen) << choice.reason;
  EXPECT_EQ(choice.candidates.size(), std::size(kHistoryWidthsMm));
  EXPECT_GT(choice.candidates.front().log_marginal_likelihood, choice.without_log_likelihood + 20.0);

  const SequenceExport out =
      train_and_export_sequence(s.data, train, validation, nullptr, geometry, options, true, 0, 0);
  ASSERT_TRUE(out.history.chosen);
  EXPECT_TRUE(model::takes_history(out.result.model.encoding));
  const double with = out.result.validation.compensated.position_mm;
  const double without = out.joints_only_validation.compensated.position_mm;
  EXPECT_LT(with, 0.65 * without) << "with " << with << " mm, without " << without << " mm";
  EXPECT_NEAR(out.result.firmware.compensated.position_mm, with, 2e-3);
  model::ImageView view{};
  ASSERT_EQ(model::parse_image(out.result.image.data(), out.result.image.size(), view), model::ImageStatus::ok);
  // 2.5 for the encoding, 2.6 for the variance block's flag.
  EXPECT_EQ(view.version_minor, model::kImageVersionMinorHeldOutThreshold);
  EXPECT_GT(view.variance_rank, 0u);
}

// The same robot without the effect: the history is searched and left out,
// and the image is the one the sequence gives without the offer.
TEST(HistoryInputs, AreLeftOutWhereTheTipDoesNotDependOnThem) {
  const auto geometry = test::two_segment_geometry();
  const test::SyntheticSequence s = test::synthetic_sequence(geometry, {}, {400}, 21, 0.05, 0.0);
  const std::vector<int> train = rows_from(0, 300), validation = rows_from(300, 100);
  TrainingOptions options = quick_options();
  const SequenceExport offered =
      train_and_export_sequence(s.data, train, validation, nullptr, geometry, options, true, 0, 0);
  EXPECT_TRUE(offered.history.searched);
  EXPECT_FALSE(offered.history.chosen) << offered.history.reason;
  options.offer_history = false;
  const SequenceExport not_offered =
      train_and_export_sequence(s.data, train, validation, nullptr, geometry, options, true, 0, 0);
  EXPECT_FALSE(not_offered.history.searched);
  EXPECT_EQ(offered.result.image, not_offered.result.image);
}

// Four segments' history inputs would take 24 inputs: not offered.
TEST(HistoryInputs, AreNotOfferedBeyondTheBoardsInputs) {
  const auto geometry = model::RobotGeometry<double>::uniform(4, 110.0, 60.0);
  const test::SyntheticSequence s = test::synthetic_sequence(geometry, {}, {60}, 5);
  const HistoryChoice choice = choose_history_inputs(s.data, rows_from(0, 60), {}, geometry, quick_options());
  EXPECT_FALSE(choice.searched);
  EXPECT_FALSE(choice.chosen);
  EXPECT_NE(choice.reason.find("exceed the board's"), std::string::npos) << choice.reason;
}

}  // namespace
}  // namespace cdcr::training
