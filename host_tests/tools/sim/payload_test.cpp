// The payload the end platform carries: a known input of each sample that
// loads the tip through gravity. Without it (or with none) the simulator is
// what it was, bit for bit; with it the tip sags further along gravity, by
// what a cantilever's tip load gives, growing smoothly with the mass.

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/model/chain.hpp>
#include <cdcr/model/units.hpp>

#include "sim/data_collection.hpp"
#include "sim/simulated_robot.hpp"
#include "sim/workspace_sampler.hpp"
#include "sim_test_types.hpp"

namespace cdcr::sim {
namespace {

using namespace test_types;

Cables straight_cables(int segments = 4) { return Cables::Constant(4 * segments, 120.0); }

std::vector<Cables> workspace_cables(double theta_max_rad, int count, std::uint64_t seed = 5) {
  WorkspaceSampler sampler(kPrototype, theta_max_rad, seed);
  std::vector<Cables> cables;
  for (int i = 0; i < count; ++i) cables.push_back(sampler.next().cables_mm);
  cables.push_back(straight_cables());
  return cables;
}

bool identical(const Pose& a, const Pose& b) { return a.rotation == b.rotation && a.position_mm == b.position_mm; }

SimulatorConfig with_payload(double min_kg, double max_kg, SimulatorConfig config = {}) {
  config.payload.enabled = true;
  config.payload.min_kg = min_kg;
  config.payload.max_kg = max_kg;
  return config;
}

// Gravity alone, and only the payload weighs: the load case of a textbook
// cantilever with a tip force.
SimulatorConfig tip_load_only(const Vec3& gravity_direction) {
  SimulatorConfig config = SimulatorConfig::nominal_only();
  config.gravity.enabled = true;
  config.gravity.direction = gravity_direction;
  config.gravity.segment_mass_kg = 0.0;
  config.gravity.platform_mass_kg = 0.0;
  return config;
}

TEST(SimulatorPayload, NoPayloadIsTheRobotWithoutOne) {
  for (const double theta_max : {0.2, 0.7}) {
    SimulatedRobot a(kPrototype, SimulatorConfig{});
    SimulatedRobot b(kPrototype, SimulatorConfig{});
    for (const Cables& cables : workspace_cables(theta_max, 30)) {
      EXPECT_EQ(a.achieved_bends(cables, 0.0), a.achieved_bends(cables));
      EXPECT_TRUE(identical(a.true_pose(cables, 0.0), a.true_pose(cables)));
      const Measurement ma = a.measure(cables, 0.0);
      const Measurement mb = b.measure(cables);
      EXPECT_TRUE(identical(ma.true_pose, mb.true_pose));
      EXPECT_TRUE(identical(ma.measured_pose, mb.measured_pose));
    }
  }
}

// A zero range writes zeros and measures exactly what no payload measures;
// any range leaves the configurations and the noise of the session as they
// were (the payload has a stream of its own).
TEST(SimulatorPayload, TheRangeChangesOnlyThePayloadAndWhatItWeighs) {
  for (const std::uint64_t session : {0u, 3u}) {
    SimulatorConfig plain;
    plain.session = session;
    SimulatedRobot without(kPrototype, plain);
    SimulatedRobot zero(kPrototype, with_payload(0.0, 0.0, plain));
    SimulatedRobot loaded(kPrototype, with_payload(0.0, 1.0, plain));
    const std::vector<CollectedSample> a = collect(without, 200);
    const std::vector<CollectedSample> b = collect(zero, 200);
    const std::vector<CollectedSample> c = collect(loaded, 200);
    int moved = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].payload_kg, 0.0);
      EXPECT_EQ(b[i].payload_kg, 0.0);
      EXPECT_EQ(b[i].cables_mm, a[i].cables_mm);
      EXPECT_TRUE(identical(b[i].measurement.true_pose, a[i].measurement.true_pose));
      EXPECT_TRUE(identical(b[i].measurement.measured_pose, a[i].measurement.measured_pose));
      EXPECT_EQ(c[i].cables_mm, a[i].cables_mm);
      EXPECT_TRUE(identical(c[i].nominal_pose, a[i].nominal_pose));
      if (!identical(c[i].measurement.true_pose, a[i].measurement.true_pose)) ++moved;
    }
    EXPECT_GE(moved, 199);  // all but a payload of exactly 0
  }
}

TEST(SimulatorPayload, PayloadsAreUniformInTheRangeAndFollowTheSession) {
  SimulatedRobot robot(kPrototype, with_payload(0.5, 1.5));
  const std::vector<CollectedSample> samples = collect(robot, 4000);
  double sum = 0.0, low = std::numeric_limits<double>::infinity(), high = -low;
  int below_one = 0;
  for (const CollectedSample& s : samples) {
    sum += s.payload_kg;
    low = std::min(low, s.payload_kg);
    high = std::max(high, s.payload_kg);
    if (s.payload_kg < 1.0) ++below_one;
  }
  EXPECT_GE(low, 0.5);
  EXPECT_LT(high, 1.5);
  EXPECT_LT(low, 0.51);
  EXPECT_GT(high, 1.49);
  // Mean 1, sigma of the mean 1/sqrt(12 * 4000) = 0.0046.
  EXPECT_NEAR(sum / 4000.0, 1.0, 0.02);
  EXPECT_NEAR(below_one, 2000, 130);  // sigma 32

  // The same session draws the same payloads; another session others.
  SimulatedRobot again(kPrototype, with_payload(0.5, 1.5));
  SimulatorConfig other_session = with_payload(0.5, 1.5);
  other_session.session = 1;
  SimulatedRobot other(kPrototype, other_session);
  const std::vector<CollectedSample> same = collect(again, 20);
  const std::vector<CollectedSample> different = collect(other, 20);
  int equal = 0;
  for (std::size_t i = 0; i < same.size(); ++i) {
    EXPECT_EQ(same[i].payload_kg, samples[i].payload_kg);
    if (different[i].payload_kg == samples[i].payload_kg) ++equal;
  }
  EXPECT_EQ(equal, 0);
}

// Derived by hand for small loads: a tip force F across the straight robot
// bends segment i (0-based, from the base) by theta_i = F (n - i) L / K, K =
// EI / L + 2 k r^2, its lever arm being the distance to the tip. An arc bent
// by theta moves its end sideways by L theta / 2 and tilts it by theta, which
// the straight segments beyond carry (n - i - 1) L further; so the tip moves
// by F L^2 / K * sum (n - i)(n - i - 1/2) along the force, and turns by
// F L / K * sum (n - i) about the axis z x F.
TEST(SimulatorPayload, SmallPayloadsFollowTheCantileverWithATipLoad) {
  const double L = 120.0, r = 67.0;
  const SimulatorConfig reference = tip_load_only(Vec3(-1.0, 0.0, 0.0));
  const double K = reference.structure.backbone_bending_stiffness_n_mm2 / L +
                   2.0 * reference.structure.cable_stiffness_n_per_mm * r * r;
  const double g = reference.gravity.acceleration_m_per_s2;
  const double lever_sum = 4.0 * 3.5 + 3.0 * 2.5 + 2.0 * 1.5 + 1.0 * 0.5;  // 25
  const double mass_kg = 1e-3;
  const double expected_mm = mass_kg * g * L * L / K * lever_sum;
  const double expected_rad = mass_kg * g * L / K * 10.0;

  for (const Vec3& down : {Vec3(-1.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0), Vec3(0.6, -0.8, 0.0)}) {
    SCOPED_TRACE(testing::Message() << "gravity " << down.transpose());
    SimulatedRobot robot(kPrototype, tip_load_only(down));
    const Pose unloaded = robot.true_pose(straight_cables());
    const Pose loaded = robot.true_pose(straight_cables(), mass_kg);
    EXPECT_LT((unloaded.position_mm - Vec3(0.0, 0.0, 480.0)).norm(), 1e-9);
    const Vec3 moved = loaded.position_mm - unloaded.position_mm;
    // Along gravity, to first order in the load (the shortening along z is
    // second order).
    EXPECT_NEAR(moved.dot(down), expected_mm, 1e-3 * expected_mm);
    EXPECT_LT((moved - moved.dot(down) * down).norm(), 1e-3 * expected_mm);
    // The end disk's axis turns towards the ground by the sum of the bends.
    const Vec3 axis = loaded.rotation.col(2);
    EXPECT_NEAR(std::asin(axis.dot(down)), expected_rad, 1e-3 * expected_rad);
  }
  EXPECT_NEAR(expected_mm, 0.0829, 1e-4);  // 83 mm per kg
}

// The default robot, mounted horizontally (gravity -x in the base frame),
// anywhere in its workspace: more payload, more sag along gravity, and
// smoothly so; in the paper's workspace, also a steeper end disk.
TEST(SimulatorPayload, MorePayloadSagsTheTipFurtherAlongGravity) {
  SimulatedRobot robot(kPrototype, SimulatorConfig{});
  const Vec3 down(-1.0, 0.0, 0.0);
  for (const double theta_max : {0.2, 0.7}) {
    const bool paper_workspace = theta_max == 0.2;
    int configuration = 0;
    for (const Cables& cables : workspace_cables(theta_max, 20)) {
      SCOPED_TRACE(testing::Message() << "theta_max " << theta_max << ", configuration " << configuration++);
      const Pose unloaded = robot.true_pose(cables);
      double previous_sag = 0.0, previous_tilt = std::asin(unloaded.rotation.col(2).dot(down));
      std::vector<double> sag;
      for (int step = 1; step <= 20; ++step) {
        const Pose pose = robot.true_pose(cables, 0.1 * step);
        const Vec3 moved = pose.position_mm - unloaded.position_mm;
        const double along = moved.dot(down);
        const double tilt = std::asin(pose.rotation.col(2).dot(down));
        EXPECT_GT(along, previous_sag) << step;
        // The end disk turns towards the ground; far out in the wide
        // workspace it can face the ground already and turn past it.
        if (paper_workspace) {
          EXPECT_GT(tilt, previous_tilt) << step;
        }
        // Within the paper's workspace mostly downwards; a robot bent far
        // sideways also swings about its base (the lever arms turn with it).
        EXPECT_GT(along, (paper_workspace ? 0.8 : 0.3) * moved.norm()) << step;
        previous_sag = along;
        previous_tilt = tilt;
        sag.push_back(along);
      }
      // 1 kg moves the tip by tens of millimetres, many times the noise
      // floor (about 2.2 mm), and the response is close to linear: the
      // second differences over 0.1 kg are a small part of the first.
      EXPECT_GT(sag[9], paper_workspace ? 50.0 : 10.0);
      EXPECT_LT(sag[9], 85.0);
      for (std::size_t k = 1; k + 1 < sag.size(); ++k) {
        const double first = sag[k + 1] - sag[k];
        const double second = sag[k + 1] - 2.0 * sag[k] + sag[k - 1];
        EXPECT_LT(std::abs(second), 0.05 * first) << k;
      }
    }
  }
}

// With gravity off nothing weighs, the payload included.
TEST(SimulatorPayload, WithoutGravityThePayloadWeighsNothing) {
  SimulatorConfig config;
  config.gravity.enabled = false;
  SimulatedRobot robot(kPrototype, config);
  for (const Cables& cables : workspace_cables(0.2, 10)) {
    EXPECT_TRUE(identical(robot.true_pose(cables, 1.0), robot.true_pose(cables)));
  }
}

// The payload is known, not noise: the floor (measured against true pose)
// stays what it is without one.
TEST(SimulatorPayload, TheNoiseFloorStaysTheNoise) {
  SimulatedRobot without(kPrototype, SimulatorConfig{});
  SimulatedRobot loaded(kPrototype, with_payload(0.0, 1.0));
  const CollectionSummary a = summarize(collect(without, 1500));
  const CollectionSummary b = summarize(collect(loaded, 1500));
  EXPECT_NEAR(b.noise_floor.position_mm, a.noise_floor.position_mm, 0.05 * a.noise_floor.position_mm);
  EXPECT_NEAR(b.noise_floor.orientation_deg, a.noise_floor.orientation_deg, 0.05 * a.noise_floor.orientation_deg);
  // While the nominal model, which knows nothing of the payload, is further
  // off.
  EXPECT_GT(b.initial.position_mm, a.initial.position_mm + 10.0);
}

TEST(SimulatorPayload, RefusesPayloadsThatAreNotAMass) {
  SimulatedRobot robot(kPrototype, SimulatorConfig{});
  const Cables cables = straight_cables();
  for (const double bad : {-0.1, -std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(robot.achieved_bends(cables, bad), std::invalid_argument) << bad;
    EXPECT_THROW(robot.true_pose(cables, bad), std::invalid_argument) << bad;
    EXPECT_THROW(robot.measure(cables, bad), std::invalid_argument) << bad;
  }
  for (const auto& [min_kg, max_kg] : {std::pair{-0.5, 1.0}, std::pair{1.0, 0.5},
                                       std::pair{0.0, std::numeric_limits<double>::infinity()},
                                       std::pair{std::numeric_limits<double>::quiet_NaN(), 1.0}}) {
    EXPECT_THROW(SimulatedRobot(kPrototype, with_payload(min_kg, max_kg)), std::invalid_argument)
        << min_kg << "," << max_kg;
  }
  EXPECT_NO_THROW(SimulatedRobot(kPrototype, with_payload(0.0, 0.0)));
  EXPECT_NO_THROW(SimulatedRobot(kPrototype, with_payload(2.0, 2.0)));
}

}  // namespace
}  // namespace cdcr::sim
