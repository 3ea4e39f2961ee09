// Source 7, the cables' friction hysteresis: the simulator's own operator
// against closed forms, its rate independence, the homing move that makes
// the state known, a session recorded as a motion sequence, and nothing
// changed with it off.

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/model/hysteresis.hpp>

#include "sim/data_collection.hpp"
#include "mean_error_bounds.hpp"
#include "sim_test_types.hpp"

namespace cdcr::sim {
namespace {

using namespace test_types;

constexpr int kCables = 16;
constexpr int kOperators = CableFriction::kOperators;

SimulatorConfig hysteresis_config(std::uint64_t seed = 1, std::uint64_t session = 0) {
  SimulatorConfig config;
  config.seed = seed;
  config.session = session;
  config.use_hysteresis_session();
  return config;
}

Cables constant_cables(double length_mm) { return Cables::Constant(kCables, length_mm); }

// Every play of every cable, for exact comparisons.
std::vector<double> all_lags(const CableFriction& friction) {
  std::vector<double> lags;
  for (int c = 0; c < friction.cables(); ++c) {
    for (int k = 0; k < kOperators; ++k) lags.push_back(friction.lag_mm(c, k));
  }
  return lags;
}

double widest_mm(const CableFriction& friction, int cable) { return friction.width_mm(cable, kOperators - 1); }

// A single play of width r, saturated at +r by a long move up, then moved
// down by d: its lag is max(-r, r - d). The cable's effective length is the
// commanded one minus the weighted lags.
TEST(SimulatorHysteresis, EveryPlayFollowsItsClosedFormOnAMonotonePathAndAReversal) {
  CableFriction friction(kCables, HysteresisConfig{}, 7, 7);
  const double x0 = 120.0;
  friction.move_to(constant_cables(x0));
  const double top = x0 + 10.0;  // more than twice any width: every play saturates
  friction.move_to(constant_cables(top));
  for (int c = 0; c < kCables; ++c) {
    for (int k = 0; k < kOperators; ++k) EXPECT_EQ(friction.lag_mm(c, k), friction.width_mm(c, k)) << c << " " << k;
  }
  double travelled = 0.0;
  for (const double step : {0.01, 0.04, 0.2, 0.35, 0.4, 1.0, 2.0}) {
    travelled += step;
    friction.move_to(constant_cables(top - travelled));
    const Cables effective = friction.effective_mm();
    for (int c = 0; c < kCables; ++c) {
      double lag = 0.0;
      for (int k = 0; k < kOperators; ++k) {
        const double r = friction.width_mm(c, k);
        const double expected = std::max(-r, r - travelled);
        EXPECT_NEAR(friction.lag_mm(c, k), expected, 1e-12) << "cable " << c << " play " << k << " after " << travelled;
        lag += friction.weight(c, k) * expected;
      }
      EXPECT_NEAR(effective[c], top - travelled - lag, 1e-12) << "cable " << c << " after " << travelled;
    }
  }
}

// Right after a reversal, within the narrowest play, no play is saturated:
// the effective length moves with slope 1 - W (W the cable's total weight),
// a rounded loop rather than a dead band.
TEST(SimulatorHysteresis, TheLoopIsRoundedAfterAReversal) {
  CableFriction friction(kCables, HysteresisConfig{}, 3, 3);
  friction.move_to(constant_cables(120.0));
  friction.move_to(constant_cables(110.0));
  const Cables bottom = friction.effective_mm();
  double narrowest = widest_mm(friction, 0);
  for (int c = 0; c < kCables; ++c) narrowest = std::min(narrowest, friction.width_mm(c, 0));
  const double d = narrowest;  // a move of d from -r leaves every lag below r - 2 r_0 < r
  friction.move_to(constant_cables(110.0 + d));
  const Cables effective = friction.effective_mm();
  for (int c = 0; c < kCables; ++c) {
    double total_weight = 0.0;
    for (int k = 0; k < kOperators; ++k) total_weight += friction.weight(c, k);
    EXPECT_GE(total_weight, HysteresisConfig{}.total_weight_min - 1e-12);
    EXPECT_LE(total_weight, HysteresisConfig{}.total_weight_max + 1e-12);
    EXPECT_NEAR(effective[c] - bottom[c], (1.0 - total_weight) * d, 1e-12) << c;
  }
}

// After a long move either way the effective length trails the commanded one
// by the cable's maximum lag: the loop's half-width. Each cable draws its
// own, within the configured range, with its own shape.
TEST(SimulatorHysteresis, TheLoopHalfWidthIsTheDrawnMaximumLag) {
  const HysteresisConfig config;
  CableFriction friction(kCables, config, 11, 11);
  friction.move_to(constant_cables(120.0));
  friction.move_to(constant_cables(130.0));
  const Cables up = friction.effective_mm();
  friction.move_to(constant_cables(110.0));
  const Cables down = friction.effective_mm();
  friction.move_to(constant_cables(130.0));
  double smallest = 1e9, largest = 0.0;
  double lightest = 1e9, heaviest = 0.0;
  for (int c = 0; c < kCables; ++c) {
    const double lag = friction.max_lag_mm(c);
    EXPECT_GE(lag, config.max_lag_min_mm);
    EXPECT_LE(lag, config.max_lag_max_mm);
    EXPECT_NEAR(130.0 - up[c], lag, 1e-12) << c;
    EXPECT_NEAR(down[c] - 110.0, lag, 1e-12) << c;
    // Back up, the loop closes on the same branch.
    EXPECT_NEAR(friction.effective_mm()[c], up[c], 1e-12) << c;
    // Half the width of the loop at one commanded length: the two branches
    // are 2 L apart.
    EXPECT_NEAR((down[c] + 20.0) - up[c], 2.0 * lag, 1e-12) << c;
    // The widest play is what the homing move has to exceed twice.
    EXPECT_LT(2.0 * widest_mm(friction, c), 4.0);
    smallest = std::min(smallest, lag);
    largest = std::max(largest, lag);
    double total_weight = 0.0;
    for (int k = 0; k < kOperators; ++k) total_weight += friction.weight(c, k);
    lightest = std::min(lightest, total_weight);
    heaviest = std::max(heaviest, total_weight);
  }
  EXPECT_GT(largest - smallest, 0.1);  // per-cable lags, not one shared value
  EXPECT_GT(heaviest - lightest, 0.02);  // and per-cable shapes
}

// Only the path counts: the same path walked in finer, uneven steps leaves
// the same state.
TEST(SimulatorHysteresis, RateIndependentTheSamePathSampledFinerGivesTheSameState) {
  CableFriction coarse(kCables, HysteresisConfig{}, 5, 9);
  CableFriction fine(kCables, HysteresisConfig{}, 5, 9);
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> offset(-3.0, 3.0);
  std::uniform_int_distribution<int> substeps(2, 40);
  Cables position = constant_cables(120.0);
  coarse.move_to(position);
  fine.move_to(position);
  for (int waypoint = 0; waypoint < 60; ++waypoint) {
    Cables next(kCables);
    for (int c = 0; c < kCables; ++c) next[c] = 120.0 + offset(rng);
    coarse.move_to(next);
    const int n = substeps(rng);
    for (int s = 1; s <= n; ++s) {
      const double t = double(s) / n;
      fine.move_to(s == n ? next : Cables(position + t * t * (next - position)));  // uneven speed
    }
    position = next;
  }
  const std::vector<double> a = all_lags(coarse);
  const std::vector<double> b = all_lags(fine);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i], b[i], 1e-12) << i;
  EXPECT_LE((coarse.effective_mm() - fine.effective_mm()).cwiseAbs().maxCoeff(), 1e-12);
}

// The state before homing is unknown (it depends on the session and on
// where the robot stands); after the homing move it is the same, exactly.
TEST(SimulatorHysteresis, HomingMakesTheStateIndependentOfTheStart) {
  std::vector<std::vector<double>> before, after;
  std::vector<Cables> effective;
  for (std::uint64_t session = 0; session < 6; ++session) {
    SimulatedRobot robot(kPrototype, hysteresis_config(1, session));
    if (session % 2 == 1) {
      // Somewhere else first: a random configuration of the session.
      WorkspaceSampler sampler(kPrototype, 0.2, 100 + session);
      robot.move_cables(sampler.next().cables_mm);
      robot.move_cables(sampler.next().cables_mm);
    }
    before.push_back(all_lags(*robot.friction()));
    home(robot);
    after.push_back(all_lags(*robot.friction()));
    effective.push_back(robot.friction()->effective_mm());
  }
  for (std::size_t s = 1; s < after.size(); ++s) {
    EXPECT_NE(before[s], before[0]) << "session " << s << " starts like session 0";
    EXPECT_EQ(after[s], after[0]) << "session " << s;
    EXPECT_EQ(effective[s], effective[0]) << "session " << s;
  }
}

// The approach leg is what makes it work: going straight home leaves a
// state that still depends on where the robot came from.
TEST(SimulatorHysteresis, GoingHomeWithoutTheApproachLeavesTheStartInTheState) {
  Cables approach_mm, home_mm;
  ASSERT_EQ(model::homing_waypoints(kPrototype, approach_mm, home_mm), model::Status::ok);
  SimulatedRobot a(kPrototype, hysteresis_config(1, 0));
  SimulatedRobot b(kPrototype, hysteresis_config(1, 1));
  a.move_cables(home_mm);
  b.move_cables(home_mm);
  EXPECT_NE(all_lags(*a.friction()), all_lags(*b.friction()));
}

TEST(SimulatorHysteresis, TheHomingMoveRefusesPlaysTooWideForIt) {
  SimulatorConfig config = hysteresis_config();
  config.hysteresis.max_lag_min_mm = 2.0;
  config.hysteresis.max_lag_max_mm = 2.5;
  SimulatedRobot robot(kPrototype, config);
  EXPECT_THROW(home(robot), std::invalid_argument);
}

// The robot remembers how it got there: the same commanded cables reached
// from two sides put the tip in two places.
TEST(SimulatorHysteresis, TheSameCablesFromTwoSidesAreTwoPoses) {
  SimulatedRobot from_below(kPrototype, hysteresis_config());
  SimulatedRobot from_above(kPrototype, hysteresis_config());
  home(from_below);
  home(from_above);
  WorkspaceSampler sampler(kPrototype, 0.2, 5);
  const Cables target = sampler.next().cables_mm;
  from_below.move_cables(target - constant_cables(3.0));
  from_above.move_cables(target + constant_cables(3.0));
  const Pose below = from_below.measure(target).true_pose;
  const Pose above = from_above.measure(target).true_pose;
  EXPECT_GT((below.position_mm - above.position_mm).norm(), 1.0);
  // Without the friction the robot has no memory.
  EXPECT_EQ(SimulatedRobot(kPrototype, SimulatorConfig{}).true_pose(target).position_mm,
            SimulatedRobot(kPrototype, SimulatorConfig{}).measure(target).true_pose.position_mm);
}

// Rows along straight lines in cable space, after the homing move: every
// row's time is the previous one plus the longest cable move at the cable
// speed plus the settling time.
TEST(SimulatorHysteresis, ASessionIsAMotionSequenceThatStartsWithHoming) {
  const SimulatorConfig config = hysteresis_config(2, 0);
  SimulatedRobot robot(kPrototype, config);
  const std::vector<CollectedSample> samples = collect(robot, 30);
  Cables approach_mm, home_mm;
  ASSERT_EQ(model::homing_waypoints(kPrototype, approach_mm, home_mm), model::Status::ok);
  const double speed = config.motion.cable_speed_mm_per_s;
  const double settle = config.motion.settle_s;
  // t = 0 at home after the homing move (powered up at home, out to the
  // approach and back: twice the same travel and settling).
  EXPECT_NEAR(home(*std::make_unique<SimulatedRobot>(kPrototype, config)),
              2.0 * ((approach_mm - home_mm).cwiseAbs().maxCoeff() / speed + settle), 1e-12);
  double expected_s = 0.0;
  Cables previous = home_mm;
  for (const CollectedSample& sample : samples) {
    ASSERT_TRUE(sample.in_sequence);
    expected_s += (sample.cables_mm - previous).cwiseAbs().maxCoeff() / speed + settle;
    EXPECT_NEAR(sample.time_s, expected_s, 1e-9);
    previous = sample.cables_mm;
  }
  for (std::size_t i = 1; i < samples.size(); ++i) EXPECT_GT(samples[i].time_s, samples[i - 1].time_s);
  const CollectionSummary summary = summarize(samples);
  EXPECT_TRUE(summary.sequence);
  EXPECT_GT(summary.hysteresis.mean_position_mm, 1.0);
  EXPECT_GE(summary.hysteresis.max_position_mm, summary.hysteresis.mean_position_mm);
}

// Another session is the same robot: the same friction, another start.
TEST(SimulatorHysteresis, AnotherSessionIsTheSameRobotFromAnotherState) {
  SimulatedRobot first(kPrototype, hysteresis_config(4, 0));
  SimulatedRobot second(kPrototype, hysteresis_config(4, 1));
  for (int c = 0; c < kCables; ++c) {
    EXPECT_EQ(first.friction()->max_lag_mm(c), second.friction()->max_lag_mm(c));
    for (int k = 0; k < kOperators; ++k) EXPECT_EQ(first.friction()->width_mm(c, k), second.friction()->width_mm(c, k));
  }
  EXPECT_NE(all_lags(*first.friction()), all_lags(*second.friction()));
}

// With the friction on, the session's noise is the small residual of
// HysteresisSessionDefaults: a floor of 0.6 to 0.8 mm.
TEST(SimulatorHysteresis, TheSessionNoiseFloorIsBelowAMillimetre) {
  SimulatedRobot robot(kPrototype, hysteresis_config(1, 0));
  const CollectionSummary summary = summarize(collect(robot, 700));
  test_types::expect_mean_error_between(summary.noise_floor, 0.6, 0.8, 0.05, 0.25);
}

// Off (the default), the robot has no state and a session is what it was:
// the other sources' values, the samples and their noise are untouched by
// the hysteresis settings.
TEST(SimulatorHysteresis, OffNothingChanges) {
  SimulatorConfig plain;
  SimulatorConfig tuned;
  tuned.hysteresis.max_lag_min_mm = 0.1;
  tuned.hysteresis.max_lag_max_mm = 0.2;
  tuned.motion.cable_speed_mm_per_s = 1.0;
  SimulatedRobot a(kPrototype, plain);
  SimulatedRobot b(kPrototype, tuned);
  EXPECT_EQ(a.friction(), nullptr);
  const std::vector<CollectedSample> sa = collect(a, 40);
  const std::vector<CollectedSample> sb = collect(b, 40);
  for (std::size_t i = 0; i < sa.size(); ++i) {
    EXPECT_FALSE(sa[i].in_sequence);
    EXPECT_EQ(sa[i].time_s, 0.0);
    EXPECT_EQ(sa[i].measurement.effective_cables_mm, sa[i].cables_mm);
    EXPECT_EQ(sa[i].measurement.measured_pose.position_mm, sb[i].measurement.measured_pose.position_mm);
    EXPECT_EQ(sa[i].measurement.measured_pose.rotation, sb[i].measurement.measured_pose.rotation);
    // The true pose is the stateless one, bit for bit.
    EXPECT_EQ(sa[i].measurement.true_pose.position_mm, a.true_pose(sa[i].cables_mm).position_mm);
    EXPECT_EQ(sa[i].measurement.true_pose.rotation, a.true_pose(sa[i].cables_mm).rotation);
  }
  EXPECT_FALSE(summarize(sa).sequence);
}

TEST(SimulatorHysteresis, RefusesBadSettings) {
  SimulatorConfig config = hysteresis_config();
  config.hysteresis.max_lag_min_mm = 0.8;
  EXPECT_THROW(SimulatedRobot(kPrototype, config), std::invalid_argument);
  config = hysteresis_config();
  config.hysteresis.total_weight_max = 1.2;
  EXPECT_THROW(SimulatedRobot(kPrototype, config), std::invalid_argument);
  config = hysteresis_config();
  config.motion.settle_s = 0.0;
  EXPECT_THROW(SimulatedRobot(kPrototype, config), std::invalid_argument);
  // A bad command leaves the friction where it was.
  SimulatedRobot robot(kPrototype, hysteresis_config());
  robot.move_cables(constant_cables(120.0));
  const std::vector<double> lags = all_lags(*robot.friction());
  Cables bad = constant_cables(130.0);
  bad[3] = std::nan("");
  EXPECT_THROW(robot.measure(bad), std::invalid_argument);
  EXPECT_EQ(all_lags(*robot.friction()), lags);
}

}  // namespace
}  // namespace cdcr::sim
