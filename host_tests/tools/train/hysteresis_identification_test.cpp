// Identification of the cables' hysteresis from a motion sequence: the
// effective lengths follow the state across sessions, a known per-cable
// operator is recovered from a sequence made here (not by the simulator),
// and a sequence too short is not identified.
#include <cmath>
#include <numeric>
#include <vector>

#include <gtest/gtest.h>

#include "hysteresis_sequence.hpp"
#include "train/hysteresis_identification.hpp"

namespace cdcr::training {
namespace {

std::vector<int> all_rows(int count) {
  std::vector<int> rows(static_cast<std::size_t>(count));
  std::iota(rows.begin(), rows.end(), 0);
  return rows;
}

TEST(EffectiveCables, EverySessionStartsAtHomeAndTheStateRunsOverEveryRow) {
  const auto geometry = test::two_segment_geometry();
  const auto hysteresis = test::known_hysteresis(geometry);
  // Two sessions; the walk's own effective lengths were computed with the
  // model's functions, one session at a time.
  const test::SyntheticSequence s = test::synthetic_sequence(geometry, hysteresis, {40, 30}, 3);
  const Eigen::MatrixXd effective = effective_cables(s.data.cables_mm, s.data.session_starts, hysteresis, geometry);
  ASSERT_EQ(effective.rows(), 70);
  EXPECT_LT((effective - s.effective_mm).cwiseAbs().maxCoeff(), 1e-12);
  // The lag is really there: up to a width per cable.
  EXPECT_GT((effective - s.data.cables_mm).cwiseAbs().maxCoeff(), 0.5);
  // An empty model leaves the commanded lengths.
  EXPECT_EQ(effective_cables(s.data.cables_mm, s.data.session_starts, {}, geometry), s.data.cables_mm);
}

// A recording without the homing move: each session starts at power-up, the
// lags anywhere within their widths (their midpoint 0: the first row's
// effective lengths are its commanded ones), and once every cable has moved
// twice its width one way the state is the homed run's, bit for bit.
TEST(EffectiveCables, APowerUpSessionStartsUnknownAndBecomesTheHomedOne) {
  const auto geometry = test::two_segment_geometry();
  const auto hysteresis = test::known_hysteresis(geometry);
  const test::SyntheticSequence s = test::synthetic_sequence(geometry, hysteresis, {120, 80}, 3);
  const Eigen::MatrixXd homed = effective_cables(s.data.cables_mm, s.data.session_starts, hysteresis, geometry);
  const Eigen::MatrixXd power_up = effective_cables(s.data.cables_mm, s.data.session_starts, hysteresis, geometry,
                                                    model::SessionStart::power_up);
  for (const int first : {0, 120}) {
    EXPECT_EQ(power_up.row(first), s.data.cables_mm.row(first)) << "session at " << first;
    EXPECT_GT((power_up.row(first) - homed.row(first)).cwiseAbs().maxCoeff(), 0.1);
  }
  // Every cable has closed its interval by the end of each session.
  EXPECT_EQ(power_up.row(119), homed.row(119));
  EXPECT_EQ(power_up.row(199), homed.row(199));
  // The training set of a recording without the homing move reads it so.
  dataset::Dataset data = s.data;
  data.sessions_homed = false;
  const TrainingSet set = make_sequence_training_set(data, hysteresis, geometry, model::InputEncoding::bend_vector);
  EXPECT_EQ(set.cables_mm, power_up);
}

TEST(EffectiveCables, BadSessionStartsAreRefused) {
  const auto geometry = test::two_segment_geometry();
  const auto hysteresis = test::known_hysteresis(geometry);
  const test::SyntheticSequence s = test::synthetic_sequence(geometry, hysteresis, {10}, 3);
  EXPECT_THROW(effective_cables(s.data.cables_mm, {}, hysteresis, geometry), std::invalid_argument);
  EXPECT_THROW(effective_cables(s.data.cables_mm, {0, 5, 5}, hysteresis, geometry), std::invalid_argument);
  EXPECT_THROW(effective_cables(s.data.cables_mm, {0, 10}, hysteresis, geometry), std::invalid_argument);
}

TEST(SequenceTrainingSet, KeepsTheCommandedLengthsAndFitsOnTheEffectiveOnes) {
  const auto geometry = test::two_segment_geometry();
  const auto hysteresis = test::known_hysteresis(geometry);
  const test::SyntheticSequence s = test::synthetic_sequence(geometry, hysteresis, {20, 20}, 4);
  const TrainingSet set =
      make_sequence_training_set(s.data, hysteresis, geometry, model::InputEncoding::bend_vector);
  EXPECT_EQ(set.commanded_mm, s.data.cables_mm);
  EXPECT_LT((set.cables_mm - s.effective_mm).cwiseAbs().maxCoeff(), 1e-12);
  const TrainingSet held_out = set.subset({3, 25});
  EXPECT_EQ(held_out.commanded_mm.row(1), s.data.cables_mm.row(25));
  EXPECT_EQ(held_out.cables_mm.row(1), set.cables_mm.row(25));
}

// The known operator (K = 1, weight 1, per-cable widths 0.3 to 0.7 mm) on
// 500 rows in two sessions, a smooth error of a few millimetres and 0.05 mm
// of noise. The per-cable structure is chosen, every width is within
// 0.05 mm of the truth (0.02 mm seen), the weight within 0.05 of 1
// (0.985 seen), and so is the lag far from a reversal, w r, what moves the
// tip most.
TEST(HysteresisIdentification, RecoversKnownPerCableWidths) {
  const auto geometry = test::two_segment_geometry();
  const auto truth = test::known_hysteresis(geometry);
  const test::SyntheticSequence s = test::synthetic_sequence(geometry, truth, {300, 200}, 11);
  TrainingOptions options;
  options.search.restarts = 0;
  const HysteresisIdentification id = identify_hysteresis(s.data, all_rows(500), geometry, options);
  ASSERT_TRUE(id.attempted);
  ASSERT_EQ(id.sharing, HysteresisSharing::per_cable);
  ASSERT_EQ(id.model.operators, 1);
  for (int c = 0; c < truth.cables; ++c) {
    EXPECT_NEAR(id.model.widths_mm[c][0], truth.widths_mm[c][0], 0.05) << "cable " << c;
    EXPECT_NEAR(id.model.weights[c][0], 1.0, 0.05) << "cable " << c;
    EXPECT_NEAR(id.model.max_lag_mm(c), truth.max_lag_mm(c), 0.05) << "cable " << c;
  }
  EXPECT_EQ(model::check_hysteresis(id.model, geometry.cable_count()), model::HysteresisCheck::ok);
  // The candidates all ran, "none" first (and a shape of several operators
  // per cable when one beat a single operator with shared widths); the
  // likelihood preferred every hysteresis model to none.
  ASSERT_GE(id.candidates.size(), 6u);
  EXPECT_EQ(id.candidates.front().sharing, HysteresisSharing::none);
  for (std::size_t i = 1; i < id.candidates.size(); ++i) {
    EXPECT_GT(id.candidates[i].criterion, id.candidates.front().criterion) << i;
  }
}

// A sequence without play: "none" wins, every candidate's widths stay at
// zero, and no model with a width below zero is evaluated. At zero the
// split of an opposite pair (one width up, the other down) has no feasible
// step, so the per-cable search evaluates only the pairs' sums and the
// weight: once to start, then a first sweep and the refining sweeps each.
TEST(HysteresisIdentification, WithoutPlayEveryWidthStaysAtZeroAndNoneIsSearchedBelowIt) {
  const auto geometry = test::two_segment_geometry();
  const test::SyntheticSequence s = test::synthetic_sequence(geometry, {}, {300, 200}, 11);
  TrainingOptions options;
  options.search.restarts = 0;
  const HysteresisSearchOptions search;
  const HysteresisIdentification id = identify_hysteresis(s.data, all_rows(500), geometry, options, true, search);
  ASSERT_TRUE(id.attempted);
  EXPECT_EQ(id.sharing, HysteresisSharing::none);
  EXPECT_TRUE(id.model.empty());
  const HysteresisCandidate* per_cable = nullptr;
  for (const HysteresisCandidate& c : id.candidates) {
    for (int cable = 0; cable < c.model.cables; ++cable) {
      for (int k = 0; k < c.model.operators; ++k) {
        EXPECT_EQ(c.model.widths_mm[cable][k], 0.0) << to_string(c.sharing) << ", K " << c.operators;
      }
    }
    if (c.sharing == HysteresisSharing::per_cable && c.operators == 1) per_cable = &c;
  }
  ASSERT_NE(per_cable, nullptr);
  const int sums_and_weight = 2 * geometry.segment_count + 1;
  EXPECT_EQ(per_cable->likelihood_evaluations,
            1 + sums_and_weight * (search.first_sweep_steps + search.refine_sweeps * search.refine_sweep_steps));
}

TEST(HysteresisIdentification, ASequenceTooShortIsNotIdentified) {
  const auto geometry = test::two_segment_geometry();
  const auto truth = test::known_hysteresis(geometry);
  const test::SyntheticSequence s = test::synthetic_sequence(geometry, truth, {kMinHysteresisRows - 1}, 5);
  const HysteresisIdentification id =
      identify_hysteresis(s.data, all_rows(kMinHysteresisRows - 1), geometry, TrainingOptions{});
  EXPECT_FALSE(id.attempted);
  EXPECT_TRUE(id.model.empty());
  EXPECT_EQ(id.skipped_reason, "49 training rows in the sequence; identifying the hysteresis needs at least 50");
}

TEST(HysteresisIdentification, RowsWithoutTimeAreRefused) {
  const auto geometry = test::two_segment_geometry();
  test::SyntheticSequence s = test::synthetic_sequence(geometry, {}, {60}, 5);
  s.data.has_time = false;
  EXPECT_THROW(identify_hysteresis(s.data, all_rows(60), geometry, TrainingOptions{}), std::invalid_argument);
}

}  // namespace
}  // namespace cdcr::training
