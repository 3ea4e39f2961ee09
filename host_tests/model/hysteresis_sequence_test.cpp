// The effective lengths over a motion sequence (hysteresis_sequence.hpp),
// as replay and eval run them: each session starts at home, whatever the
// session before it did, and within a session the state is carried from row
// to row, as a hand-written run of the operator gives.

#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "cdcr/model/hysteresis_sequence.hpp"

namespace cdcr::model {
namespace {

HysteresisModel<float> two_operator_model(const RobotGeometry<float>& geometry) {
  HysteresisModel<float> h;
  h.cables = 4 * geometry.segment_count;
  h.operators = 2;
  for (int c = 0; c < h.cables; ++c) {
    h.widths_mm[c][0] = 0.3f + 0.02f * c;
    h.widths_mm[c][1] = 0.7f;
    h.weights[c][0] = 0.5f;
    h.weights[c][1] = 0.4f;
  }
  CableVector<float> approach, home;
  homing_waypoints(geometry, approach, home);
  compute_homing_lags(h, approach, home);
  return h;
}

// `rows` rows of a walk from home: every cable steps up to 0.8 mm either way.
Eigen::MatrixXd random_walk_from_home(const RobotGeometry<float>& geometry, int rows, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> step(-0.8, 0.8);
  CableVector<float> approach, home;
  homing_waypoints(geometry, approach, home);
  Eigen::MatrixXd commanded(rows, home.size());
  for (int i = 0; i < rows; ++i) {
    for (int c = 0; c < home.size(); ++c) {
      commanded(i, c) = home[c] + (i == 0 ? 0.0 : commanded(i - 1, c) - home[c]) + step(rng);
    }
  }
  return commanded;
}

TEST(HysteresisSequence, EachSessionStartsAtHomeAndCarriesItsStateFromRowToRow) {
  const RobotGeometry<float> geometry = RobotGeometry<float>::uniform(2, 120.0f, 67.0f);
  const HysteresisModel<float> h = two_operator_model(geometry);
  const Eigen::MatrixXd commanded = random_walk_from_home(geometry, 30, 3);
  const std::vector<int> sessions = {0, 12, 20};
  Eigen::MatrixXf effective(30, 8);
  ASSERT_EQ(effective_lengths_over_sequence(h, geometry, commanded, sessions.data(), 3, effective), Status::ok);

  // By hand.
  HysteresisState<float> state;
  for (int i = 0; i < commanded.rows(); ++i) {
    if (i == 0 || i == 12 || i == 20) ASSERT_EQ(start_at_home(state, h, geometry), Status::ok);
    const CableVector<float> row = commanded.row(i).transpose().cast<float>();
    update_hysteresis(state, h, row);
    CableVector<float> expected;
    effective_lengths(state, h, expected);
    for (int c = 0; c < 8; ++c) ASSERT_EQ(effective(i, c), expected[c]) << "row " << i << " cable " << c;
  }

  // A session does not depend on the one before it.
  Eigen::MatrixXd changed = commanded;
  changed.topRows(12).array() += 1.5;
  Eigen::MatrixXf effective_changed(30, 8);
  ASSERT_EQ(effective_lengths_over_sequence(h, geometry, changed, sessions.data(), 3, effective_changed), Status::ok);
  EXPECT_TRUE(effective_changed.bottomRows(18) == effective.bottomRows(18));
  // Without sessions the whole sequence is one, and it does.
  Eigen::MatrixXf one_session(30, 8), one_session_changed(30, 8);
  effective_lengths_over_sequence(h, geometry, commanded, nullptr, 0, one_session);
  effective_lengths_over_sequence(h, geometry, changed, nullptr, 0, one_session_changed);
  EXPECT_TRUE(one_session.topRows(12) == effective.topRows(12));
  EXPECT_FALSE(one_session.row(12) == effective.row(12));
  // The lags matter: the effective lengths are not the commanded ones.
  EXPECT_GT((effective.cast<double>() - commanded).cwiseAbs().maxCoeff(), 0.3);
}

// The history inputs of every row are those of the state the effective
// lengths' run leaves there, session by session.
TEST(HysteresisSequence, HistoryInputsFollowTheSameState) {
  const RobotGeometry<float> geometry = RobotGeometry<float>::uniform(2, 120.0f, 67.0f);
  const HysteresisModel<float> h = two_operator_model(geometry);
  const Eigen::MatrixXd commanded = random_walk_from_home(geometry, 25, 5);
  const std::vector<int> sessions = {0, 10};
  Eigen::MatrixXf effective(25, 8), history(25, 8);
  ASSERT_EQ(effective_lengths_over_sequence(h, geometry, commanded, sessions.data(), 2, effective,
                                            SessionStart::homed, &history),
            Status::ok);
  HysteresisState<float> state;
  bool moved_both_ways = false;
  for (int i = 0; i < commanded.rows(); ++i) {
    if (i == 0 || i == 10) ASSERT_EQ(start_at_home(state, h, geometry), Status::ok);
    const CableVector<float> row = commanded.row(i).transpose().cast<float>();
    update_hysteresis(state, h, row);
    for (int c = 0; c < 8; ++c) {
      const float expected = 0.5f * (state.lag_low_mm[c][1] + state.lag_high_mm[c][1]) / 0.7f;
      ASSERT_FLOAT_EQ(history(i, c), expected) << "row " << i << " cable " << c;
    }
  }
  for (int c = 0; c < 8; ++c) moved_both_ways |= history.col(c).maxCoeff() > 0.9f && history.col(c).minCoeff() < -0.9f;
  EXPECT_TRUE(moved_both_ways);
}

TEST(HysteresisSequence, RefusesRowsOfAnotherCableCount) {
  const RobotGeometry<float> geometry = RobotGeometry<float>::uniform(2, 120.0f, 67.0f);
  const HysteresisModel<float> h = two_operator_model(geometry);
  Eigen::MatrixXd commanded = Eigen::MatrixXd::Constant(3, 4, 120.0);
  Eigen::MatrixXf effective(3, 4);
  EXPECT_NE(effective_lengths_over_sequence(h, geometry, commanded, nullptr, 0, effective), Status::ok);
}

}  // namespace
}  // namespace cdcr::model
