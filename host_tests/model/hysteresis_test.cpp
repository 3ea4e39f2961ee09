// The cables' friction hysteresis (model/hysteresis.hpp) against closed
// forms written here from the definition of a play operator, not from the
// implementation: a play operator of half-width r with input x has an
// output that stays put until x has moved r away from it, then follows x at
// distance r. Its lag x - output lies in [-r, r]; the effective length is
// x - sum_k w_k lag_k.
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "cdcr/model/geometry.hpp"
#include "cdcr/model/hysteresis.hpp"

namespace cdcr::model {
namespace {

using Lengths = Eigen::VectorXd;

// A model of `cables` cables, each with the same operators.
template <typename S = double>
HysteresisModel<S> make_model(int cables, const std::vector<double>& widths, const std::vector<double>& weights) {
  HysteresisModel<S> m;
  m.cables = cables;
  m.operators = static_cast<int>(widths.size());
  for (int c = 0; c < cables; ++c) {
    for (int k = 0; k < m.operators; ++k) {
      m.widths_mm[c][k] = S(widths[k]);
      m.weights[c][k] = S(weights[k]);
    }
  }
  return m;
}

// A one-cable state with every lag known, at commanded length x.
HysteresisState<double> known_state(const HysteresisModel<double>& m, double x, const std::vector<double>& lags) {
  HysteresisState<double> s;
  reset_unknown(s, m);
  for (int k = 0; k < m.operators; ++k) {
    s.lag_low_mm[0][k] = lags[k];
    s.lag_high_mm[0][k] = lags[k];
  }
  s.commanded_mm[0] = x;
  s.has_position = true;
  return s;
}

double effective_of(const HysteresisState<double>& s, const HysteresisModel<double>& m, int cable = 0) {
  Lengths e;
  effective_lengths(s, m, e);
  return e[cable];
}

double move_to(HysteresisState<double>& s, const HysteresisModel<double>& m, double x) {
  update_hysteresis(s, m, Lengths::Constant(1, x));
  return effective_of(s, m);
}

// --- one play operator ---------------------------------------------------

TEST(Hysteresis, MonotonePathFromTheLowerStopSaturatesAfterTwiceTheWidth) {
  const double r = 0.8;
  for (const double w : {1.0, 0.6}) {
    const HysteresisModel<double> m = make_model(1, {r}, {w});
    HysteresisState<double> s = known_state(m, 100.0, {-r});
    // Lag -r at x = 100: the output sits r above the input.
    EXPECT_DOUBLE_EQ(effective_of(s, m), 100.0 + w * r);
    for (int step = 1; step <= 60; ++step) {
      const double travel = 0.05 * step;  // up to 3 mm > 2r = 1.6 mm
      const double x = 100.0 + travel;
      const double e = move_to(s, m, x);
      // The output stays at 100 + r (w = 1) until x reaches it plus r,
      // i.e. for a travel of 2r; then it follows at x - r.
      const double expected_lag = travel < 2.0 * r ? travel - r : r;
      EXPECT_NEAR(s.lag_low_mm[0][0], expected_lag, 1e-12) << "w " << w << " travel " << travel;
      EXPECT_NEAR(e, x - w * expected_lag, 1e-12) << "w " << w << " travel " << travel;
      if (travel >= 2.0 * r) {
        EXPECT_NEAR(e, x - w * r, 1e-12);
      }
    }
    // The same path in one move ends in the same state.
    HysteresisState<double> jump = known_state(m, 100.0, {-r});
    EXPECT_NEAR(move_to(jump, m, 103.0), 103.0 - w * r, 1e-12);
  }
}

TEST(Hysteresis, AReversalIsADeadBandOfTwiceTheWidthWithUnitWeight) {
  const double r = 0.7;
  for (const double w : {1.0, 0.4}) {
    const HysteresisModel<double> m = make_model(1, {r}, {w});
    // Arrive at x = 120 after a long move up: lag +r.
    HysteresisState<double> s = known_state(m, 110.0, {0.0});
    const double top = move_to(s, m, 120.0);
    EXPECT_NEAR(top, 120.0 - w * r, 1e-12);
    for (int step = 1; step <= 50; ++step) {
      const double down = 0.05 * step;  // up to 2.5 mm
      const double e = move_to(s, m, 120.0 - down);
      // Within the band the effective length falls with slope 1 - w (not at
      // all with w = 1); beyond it, with slope 1.
      const double expected = down <= 2.0 * r ? top - (1.0 - w) * down
                                               : top - (1.0 - w) * 2.0 * r - (down - 2.0 * r);
      EXPECT_NEAR(e, expected, 1e-12) << "w " << w << " down " << down;
      if (w == 1.0 && down <= 2.0 * r) {
        EXPECT_NEAR(e, top, 1e-12);
      }
    }
  }
}

// --- a Prandtl-Ishlinskii loop ------------------------------------------

TEST(Hysteresis, ThreeOperatorLoopFollowsTheClosedFormBranches) {
  const std::vector<double> r = {0.2, 0.5, 0.9};
  const std::vector<double> w = {0.2, 0.3, 0.5};
  const HysteresisModel<double> m = make_model(1, r, w);
  HysteresisState<double> s = known_state(m, 100.0, {0.0, 0.0, 0.0});
  // Saturate upwards, then a full reversal down by 2.5 mm > 2 * 0.9.
  const double top = move_to(s, m, 110.0);
  EXPECT_NEAR(top, 110.0 - (0.2 * 0.2 + 0.3 * 0.5 + 0.5 * 0.9), 1e-12);
  EXPECT_NEAR(m.max_lag_mm(0), 0.2 * 0.2 + 0.3 * 0.5 + 0.5 * 0.9, 1e-15);
  const double descent = 2.5;
  // Descending branch from the top: the drop of the effective length after
  // d of travel is sum_k w_k max(0, d - 2 r_k) (sum w = 1).
  const auto branch = [&](double d) {
    double sum = 0.0;
    for (int k = 0; k < 3; ++k) sum += w[k] * std::max(0.0, d - 2.0 * r[k]);
    return sum;
  };
  double bottom = 0.0;
  for (int step = 1; step <= 50; ++step) {
    const double d = descent * step / 50.0;
    bottom = move_to(s, m, 110.0 - d);
    EXPECT_NEAR(top - bottom, branch(d), 1e-12) << "descending " << d;
  }
  // Ascending branch after the full reversal: the same shape, rising.
  for (int step = 1; step <= 50; ++step) {
    const double u = descent * step / 50.0;
    const double e = move_to(s, m, 110.0 - descent + u);
    EXPECT_NEAR(e - bottom, branch(u), 1e-12) << "ascending " << u;
  }
  // The loop closes where it started.
  EXPECT_NEAR(effective_of(s, m), top, 1e-12);
  // Its widest point, at the middle of the stroke, is sum w_k min(d/2, ...)
  // apart between branches: check one point against both branch formulas.
  HysteresisState<double> down = s;
  const double e_down = move_to(down, m, 110.0 - descent / 2.0);
  const double e_up = bottom + branch(descent / 2.0);
  EXPECT_NEAR(e_down, top - branch(descent / 2.0), 1e-12);
  EXPECT_GT(e_down - e_up, 0.3);
}

// --- the unknown state ---------------------------------------------------

TEST(Hysteresis, UnknownStateClosesAfterTwiceTheWidthInOneDirectionAndNotBefore) {
  const double r = 0.5;  // 2r = 1 mm, exact in binary
  const HysteresisModel<double> m = make_model(1, {r}, {0.8});
  HysteresisState<double> s;
  reset_unknown(s, m);
  EXPECT_FALSE(s.known());
  EXPECT_EQ(s.lag_low_mm[0][0], -r);
  EXPECT_EQ(s.lag_high_mm[0][0], r);
  update_hysteresis(s, m, Lengths::Constant(1, 100.0));  // records the position only
  EXPECT_EQ(s.lag_high_mm[0][0] - s.lag_low_mm[0][0], 2.0 * r);

  // Up by t < 2r: the interval is [-r + t, r].
  HysteresisState<double> partial = s;
  update_hysteresis(partial, m, Lengths::Constant(1, 100.999));
  EXPECT_FALSE(partial.known());
  EXPECT_NEAR(partial.lag_low_mm[0][0], -r + 0.999, 1e-12);
  EXPECT_EQ(partial.lag_high_mm[0][0], r);

  // Exactly 2r, in three moves: closed, exactly, at +r.
  update_hysteresis(s, m, Lengths::Constant(1, 100.25));
  update_hysteresis(s, m, Lengths::Constant(1, 100.5));
  EXPECT_FALSE(s.known());
  update_hysteresis(s, m, Lengths::Constant(1, 101.0));
  EXPECT_TRUE(s.known());
  EXPECT_EQ(s.lag_low_mm[0][0], r);
  EXPECT_EQ(s.lag_high_mm[0][0], r);

  // 3r of travel with a reversal in the middle does not close it.
  HysteresisState<double> reversing;
  reset_unknown(reversing, m);
  update_hysteresis(reversing, m, Lengths::Constant(1, 100.0));
  update_hysteresis(reversing, m, Lengths::Constant(1, 100.75));
  update_hysteresis(reversing, m, Lengths::Constant(1, 100.0));
  EXPECT_FALSE(reversing.known());
  EXPECT_EQ(reversing.lag_low_mm[0][0], -r);
  EXPECT_EQ(reversing.lag_high_mm[0][0], -0.25);

  // The same in float: the ends meet exactly.
  const HysteresisModel<float> mf = make_model<float>(1, {r}, {0.8});
  HysteresisState<float> sf;
  reset_unknown(sf, mf);
  update_hysteresis(sf, mf, Eigen::VectorXf::Constant(1, 100.0f));
  update_hysteresis(sf, mf, Eigen::VectorXf::Constant(1, 100.9f));
  EXPECT_FALSE(sf.known());
  update_hysteresis(sf, mf, Eigen::VectorXf::Constant(1, 101.0f));
  EXPECT_TRUE(sf.known());
}

TEST(Hysteresis, UncertaintyIsTheWeightedHalfWidthOfTheLagIntervals) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const HysteresisModel<double> m = make_model(4, {0.3, 0.9, 1.6}, {0.25, 0.35, 0.3});
  for (int trial = 0; trial < 50; ++trial) {
    HysteresisState<double> s;
    reset_unknown(s, m);
    for (int c = 0; c < 4; ++c) {
      s.commanded_mm[c] = 100.0 + 10.0 * unit(rng);
      for (int k = 0; k < 3; ++k) {
        const double r = m.widths_mm[c][k];
        const double a = -r + 2.0 * r * unit(rng);
        const double b = -r + 2.0 * r * unit(rng);
        s.lag_low_mm[c][k] = std::min(a, b);
        s.lag_high_mm[c][k] = std::max(a, b);
      }
    }
    Lengths effective, uncertainty;
    effective_lengths(s, m, effective, &uncertainty);
    ASSERT_EQ(uncertainty.size(), 4);
    for (int c = 0; c < 4; ++c) {
      double spread = 0.0;
      double midpoint_lag = 0.0;
      for (int k = 0; k < 3; ++k) {
        spread += m.weights[c][k] * (s.lag_high_mm[c][k] - s.lag_low_mm[c][k]) / 2.0;
        midpoint_lag += m.weights[c][k] * (s.lag_high_mm[c][k] + s.lag_low_mm[c][k]) / 2.0;
      }
      EXPECT_NEAR(uncertainty[c], spread, 1e-12);
      EXPECT_NEAR(effective[c], s.commanded_mm[c] - midpoint_lag, 1e-12);
      // The bound holds: any lag in the intervals gives an effective length
      // within the uncertainty of the estimate.
      double extreme = s.commanded_mm[c];
      for (int k = 0; k < 3; ++k) extreme -= m.weights[c][k] * s.lag_high_mm[c][k];
      EXPECT_NEAR(std::abs(effective[c] - extreme), uncertainty[c], 1e-12);
    }
  }
  // Known: no uncertainty.
  HysteresisState<double> homed;
  reset_to_homing(homed, m);
  Lengths effective, uncertainty;
  effective_lengths(homed, m, effective, &uncertainty);
  EXPECT_EQ(uncertainty.cwiseAbs().maxCoeff(), 0.0);
}

// --- the inverse ---------------------------------------------------------

// A random model of one cable: 1..4 operators, widths up to the limit (some
// zero), weights summing to 1 (dead bands) or less.
HysteresisModel<double> random_model(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const int operators = 1 + static_cast<int>(rng() % kMaxHysteresisOperators);
  std::vector<double> widths(operators), weights(operators);
  double total = 0.0;
  for (int k = 0; k < operators; ++k) {
    widths[k] = unit(rng) < 0.1 ? 0.0 : kMaxHysteresisWidthMm * unit(rng);
    weights[k] = 0.05 + unit(rng);
    total += weights[k];
  }
  const double weight_sum = unit(rng) < 0.5 ? 1.0 : 0.3 + 0.7 * unit(rng);
  for (double& w : weights) w *= weight_sum / total;
  return make_model(1, widths, weights);
}

// A random state: each lag at a stop, inside, or (unknown) an interval.
HysteresisState<double> random_state(const HysteresisModel<double>& m, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  HysteresisState<double> s;
  reset_unknown(s, m);
  s.commanded_mm[0] = 90.0 + 20.0 * unit(rng);
  s.has_position = true;
  const bool unknown = unit(rng) < 0.3;
  for (int k = 0; k < m.operators; ++k) {
    const double r = m.widths_mm[0][k];
    const double pick = unit(rng);
    double lag = pick < 0.3 ? r : (pick < 0.6 ? -r : -r + 2.0 * r * unit(rng));
    s.lag_low_mm[0][k] = lag;
    s.lag_high_mm[0][k] = lag;
    if (unknown) {
      const double other = -r + 2.0 * r * unit(rng);
      s.lag_low_mm[0][k] = std::min(lag, other);
      s.lag_high_mm[0][k] = std::max(lag, other);
    }
  }
  return s;
}

// --- the history inputs --------------------------------------------------

// Where the cable last moved, from the last operator: 0 while nothing is
// known, +-1 once it has moved twice the width one way, the lag over the
// width inside a reversal (by hand: a move back by d from the upper stop
// leaves the lag at w - d). A weight of 0 leaves the effective length the
// commanded one.
TEST(Hysteresis, HistoryInputsAreTheLastOperatorsLagOverItsWidth) {
  const HysteresisModel<double> m = make_model(1, {0.5, 0.2}, {0.6, 0.0});
  HysteresisState<double> s;
  reset_unknown(s, m);
  double h[1] = {7.0};
  history_inputs(s, m, h);
  EXPECT_EQ(h[0], 0.0);
  move_to(s, m, 10.0);
  move_to(s, m, 10.5);  // 0.5 mm up: the interval [-0.2, 0.2] + 0.5 closes at the upper stop
  history_inputs(s, m, h);
  EXPECT_DOUBLE_EQ(h[0], 1.0);
  move_to(s, m, 10.45);  // 0.05 mm back: lag 0.15
  history_inputs(s, m, h);
  EXPECT_NEAR(h[0], 0.15 / 0.2, 1e-12);
  move_to(s, m, 9.0);
  history_inputs(s, m, h);
  EXPECT_DOUBLE_EQ(h[0], -1.0);
  // Only the first operator lags the effective length: its lag is -0.5 after
  // the long move down, weight 0.6.
  EXPECT_NEAR(effective_of(s, m), 9.0 + 0.6 * 0.5, 1e-12);
  // Half known: after 0.2 mm up from power-up the interval is [0, 0.2].
  reset_unknown(s, m);
  move_to(s, m, 10.0);
  move_to(s, m, 10.2);
  history_inputs(s, m, h);
  EXPECT_NEAR(h[0], 0.5, 1e-12);
}

TEST(Hysteresis, CommandedForEffectiveInvertsTheOperatorInBothDirections) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int dead_band_moves = 0;
  int unknown_moves = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const HysteresisModel<double> m = random_model(rng);
    const HysteresisState<double> s = random_state(m, rng);
    const double e0 = effective_of(s, m);
    // Small targets land inside dead bands and partly saturated stretches,
    // large ones beyond every breakpoint.
    const double magnitude = unit(rng) < 0.5 ? 0.5 * unit(rng) : 6.0 * unit(rng);
    const double target = e0 + (unit(rng) < 0.5 ? -magnitude : magnitude);
    const double x = commanded_for_effective(s, m, 0, target);
    HysteresisState<double> moved = s;
    EXPECT_NEAR(move_to(moved, m, x), target, 1e-10) << "trial " << trial;
    // The cable moves towards the target, and no further than it must:
    // a little less travel falls short.
    const double direction = target > e0 ? 1.0 : -1.0;
    EXPECT_GE(direction * (x - s.commanded_mm[0]), direction * (target - e0) - 1e-12) << "trial " << trial;
    HysteresisState<double> short_of = s;
    const double shortfall = direction * (target - move_to(short_of, m, x - direction * 1e-6));
    EXPECT_GT(shortfall, 0.0) << "trial " << trial;
    double weight_sum = 0.0;
    for (int k = 0; k < m.operators; ++k) weight_sum += m.weights[0][k];
    if (std::abs(weight_sum - 1.0) < 1e-12 && std::abs(x - s.commanded_mm[0]) > std::abs(target - e0) + 1e-3) {
      ++dead_band_moves;
    }
    if (!s.known()) ++unknown_moves;
  }
  EXPECT_GT(dead_band_moves, 500);
  EXPECT_GT(unknown_moves, 500);
}

TEST(Hysteresis, ATargetAlreadyMetInADeadBandLeavesTheCable) {
  const HysteresisModel<double> m = make_model(1, {0.6}, {1.0});
  const HysteresisState<double> s = known_state(m, 100.0, {0.1});
  EXPECT_EQ(commanded_for_effective(s, m, 0, effective_of(s, m)), 100.0);
  // Up by 0.2: the band ends after 0.5 mm of travel, then slope 1.
  EXPECT_NEAR(commanded_for_effective(s, m, 0, effective_of(s, m) + 0.2), 100.7, 1e-12);
  // Down by 0.2: the band ends after 0.7 mm.
  EXPECT_NEAR(commanded_for_effective(s, m, 0, effective_of(s, m) - 0.2), 99.1, 1e-12);
}

// --- float against double ------------------------------------------------

TEST(Hysteresis, FloatFollowsDoubleOnALongRandomPath) {
  const std::vector<double> widths = {0.15, 0.45, 1.1};
  const std::vector<double> weights = {0.3, 0.3, 0.3};
  const HysteresisModel<double> md = make_model<double>(4, widths, weights);
  const HysteresisModel<float> mf = make_model<float>(4, widths, weights);
  HysteresisState<double> sd;
  HysteresisState<float> sf;
  reset_unknown(sd, md);
  reset_unknown(sf, mf);
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> step(-1.5, 1.5);
  Eigen::VectorXd x = Eigen::VectorXd::Constant(4, 118.0);
  double worst = 0.0;
  double worst_inverse = 0.0;
  for (int i = 0; i < 500; ++i) {
    for (int c = 0; c < 4; ++c) x[c] = std::round((x[c] + step(rng)) * 64.0) / 64.0;  // exact in float
    update_hysteresis(sd, md, x);
    update_hysteresis(sf, mf, Eigen::VectorXf(x.cast<float>()));
    Eigen::VectorXd ed, ud;
    Eigen::VectorXf ef, uf;
    effective_lengths(sd, md, ed, &ud);
    effective_lengths(sf, mf, ef, &uf);
    worst = std::max(worst, (ed - ef.cast<double>()).cwiseAbs().maxCoeff());
    worst = std::max(worst, (ud - uf.cast<double>()).cwiseAbs().maxCoeff());
    const double target = ed[0] + step(rng);
    const double xd = commanded_for_effective(sd, md, 0, target);
    const float xf = commanded_for_effective(sf, mf, 0, static_cast<float>(target));
    worst_inverse = std::max(worst_inverse, std::abs(xd - double(xf)));
  }
  EXPECT_TRUE(sd.known());
  EXPECT_TRUE(sf.known());
  EXPECT_LT(worst, 1e-4);
  // Slope 1 - 0.9 at worst: float's rounding of the target grows tenfold.
  EXPECT_LT(worst_inverse, 5e-4);
}

// --- the homing move -----------------------------------------------------

// Eq. (2), as kinematics-conventions.md writes it, for cable j = 1..4.
double cable_length(double length_mm, double radius_mm, double alpha, double theta, int j) {
  const double pi = 3.14159265358979323846;
  const double half = theta / 2.0;
  return 2.0 * (length_mm / theta) * std::sin(half) - 2.0 * radius_mm * std::cos(alpha + (j - 1) * pi / 2.0) * std::sin(half);
}

TEST(Hysteresis, HomingWaypointsAreTheBentAndStraightRobot) {
  RobotGeometry<double> g = RobotGeometry<double>::prototype();
  g.segments[2].anchor_radius_mm = 60.0;  // one segment different
  g.segments[3].backbone_length_mm = 110.0;
  CableVector<double, kMaxSegments> approach, home;
  ASSERT_EQ(homing_waypoints(g, approach, home), Status::ok);
  ASSERT_EQ(approach.size(), 16);
  ASSERT_EQ(home.size(), 16);
  const double quarter = 0.78539816339744831;
  for (int i = 0; i < 4; ++i) {
    const double length = g.segments[i].backbone_length_mm;
    const double radius = g.segments[i].anchor_radius_mm;
    for (int j = 1; j <= 4; ++j) {
      EXPECT_NEAR(home[4 * i + j - 1], length, 1e-12);
      EXPECT_NEAR(approach[4 * i + j - 1], cable_length(length, radius, quarter, 0.1, j), 1e-9) << i << " " << j;
    }
  }
  // The shortest way home: a shortening cable, 2 r sin(0.05) cos(45 deg)
  // less the backbone's straightening.
  const double expected_travel = 2.0 * 60.0 * std::sin(0.05) * std::cos(quarter) - (120.0 - 20.0 * 120.0 * std::sin(0.05));
  EXPECT_NEAR(homing_travel_mm(approach, home), expected_travel, 1e-9);
  EXPECT_GT(homing_travel_mm(approach, home), 2.0 * kMaxHysteresisWidthMm);

  RobotGeometry<double> empty;
  EXPECT_EQ(homing_waypoints(empty, approach, home), Status::invalid_segment_count);
}

TEST(Hysteresis, HomingLeavesEachLagAtTheStopOfItsCablesDirectionHome) {
  const RobotGeometry<double> g = RobotGeometry<double>::prototype();
  HysteresisModel<double> m = make_model(16, {0.3, 0.7, 1.9}, {0.3, 0.3, 0.3});
  CableVector<double, kMaxSegments> approach, home;
  ASSERT_EQ(homing_waypoints(g, approach, home), Status::ok);
  compute_homing_lags(m, approach, home);
  EXPECT_EQ(check_hysteresis(m, 16), HysteresisCheck::ok);
  // On the way home (alpha = 45 deg, theta 0.1 -> 0) eq. (2) makes cable j
  // lengthen when cos(45 deg + (j - 1) 90 deg) > 0: cables 1 and 4 lengthen
  // (lag +r), cables 2 and 3 shorten (lag -r), in every segment.
  const double expected_sign[4] = {+1.0, -1.0, -1.0, +1.0};
  for (int c = 0; c < 16; ++c) {
    const int j = c % 4 + 1;
    const double lengthens =
        cable_length(120.0, 67.0, 0.0, 1e-9, j) - cable_length(120.0, 67.0, 0.78539816339744831, 0.1, j);
    ASSERT_EQ(lengthens > 0.0, expected_sign[c % 4] > 0.0) << "cable " << c;
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(m.homing_lag_mm[c][k], expected_sign[c % 4] * m.widths_mm[c][k]) << "cable " << c << " op " << k;
    }
  }

  // Whatever came before, the homing move leaves the same state.
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> wander(-6.0, 6.0);
  for (int trial = 0; trial < 5; ++trial) {
    HysteresisState<double> s;
    reset_unknown(s, m);
    Lengths x = home;
    for (int i = 0; i < 20; ++i) {
      for (int c = 0; c < 16; ++c) x[c] = home[c] + wander(rng);
      update_hysteresis(s, m, x);
    }
    update_hysteresis(s, m, approach);
    update_hysteresis(s, m, home);
    ASSERT_TRUE(s.known());
    for (int c = 0; c < 16; ++c) {
      for (int k = 0; k < 3; ++k) EXPECT_EQ(s.lag_low_mm[c][k], m.homing_lag_mm[c][k]);
    }
  }

  // A session starts there: at the home lengths, every lag the homing lag.
  HysteresisState<double> session;
  ASSERT_EQ(start_at_home(session, m, g), Status::ok);
  EXPECT_TRUE(session.has_position);
  EXPECT_TRUE(session.known());
  Lengths effective;
  effective_lengths(session, m, effective);
  for (int c = 0; c < 16; ++c) {
    EXPECT_EQ(session.commanded_mm[c], home[c]);
    const double expected_lag = expected_sign[c % 4] * (0.3 * 0.3 + 0.3 * 0.7 + 0.3 * 1.9);
    EXPECT_NEAR(effective[c], 120.0 - expected_lag, 1e-12) << "cable " << c;
  }
}

// --- what check_hysteresis refuses ---------------------------------------

TEST(Hysteresis, CheckRefusesModelsItCannotUse) {
  const auto good = [] {
    HysteresisModel<double> m = make_model(8, {0.2, 0.8}, {0.5, 0.5});
    for (int c = 0; c < 8; ++c) m.homing_lag_mm[c][1] = -0.8;
    return m;
  };
  EXPECT_EQ(check_hysteresis(good(), 8), HysteresisCheck::ok);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();

  EXPECT_EQ(check_hysteresis(good(), 12), HysteresisCheck::bad_counts);
  {
    HysteresisModel<double> m = good();
    m.operators = 0;
    EXPECT_EQ(check_hysteresis(m, 8), HysteresisCheck::bad_counts);
    m.operators = kMaxHysteresisOperators + 1;
    EXPECT_EQ(check_hysteresis(m, 8), HysteresisCheck::bad_counts);
  }
  {
    HysteresisModel<double> m = good();
    m.cables = kMaxCables + 4;
    EXPECT_EQ(check_hysteresis(m, 4 * (kMaxSegments + 1)), HysteresisCheck::bad_counts);
  }
  for (const double width : {nan, inf, -0.1, kMaxHysteresisWidthMm * 1.01}) {
    HysteresisModel<double> m = good();
    m.widths_mm[5][1] = width;
    EXPECT_EQ(check_hysteresis(m, 8), HysteresisCheck::bad_width) << width;
  }
  {
    HysteresisModel<double> m = good();
    m.widths_mm[5][1] = kMaxHysteresisWidthMm;
    EXPECT_EQ(check_hysteresis(m, 8), HysteresisCheck::ok);
    m.widths_mm[5][0] = 0.0;
    m.homing_lag_mm[5][0] = 0.0;
    EXPECT_EQ(check_hysteresis(m, 8), HysteresisCheck::ok);
  }
  for (const double weight : {nan, inf, -0.01, 0.51}) {
    HysteresisModel<double> m = good();
    m.weights[7][0] = weight;
    EXPECT_EQ(check_hysteresis(m, 8), HysteresisCheck::bad_weight) << weight;
  }
  for (const double lag : {nan, -0.81, 0.8000001}) {
    HysteresisModel<double> m = good();
    m.homing_lag_mm[3][1] = lag;
    EXPECT_EQ(check_hysteresis(m, 8), HysteresisCheck::bad_homing_lag) << lag;
  }
  // Float weights that sum to 1 only up to their rounding are accepted.
  HysteresisModel<float> mf = make_model<float>(4, {0.1, 0.1, 0.1}, {0.1f, 0.2f, 0.7f});
  float sum = 0.0f;
  for (int k = 0; k < 3; ++k) sum += mf.weights[0][k];
  EXPECT_EQ(check_hysteresis(mf, 4), HysteresisCheck::ok) << "sum " << sum;
}

}  // namespace
}  // namespace cdcr::model
