// Each error source of the simulated robot on its own: off it leaves the
// nominal model untouched (bit for bit), on it moves the pose the way its
// physics says, and noise only ever reaches the measured pose.

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/model/chain.hpp>
#include <cdcr/model/compensation.hpp>
#include <cdcr/model/units.hpp>

#include "sim/simulated_robot.hpp"
#include "sim/workspace_sampler.hpp"
#include "sim_test_types.hpp"

namespace cdcr::sim {
namespace {

using namespace test_types;
using model::kPi;

Pose nominal_pose(const Cables& cables, const Geometry& geometry = kPrototype) {
  Joints joints;
  Pose pose;
  EXPECT_EQ(model::joints_from_cables(cables, geometry, joints), model::Status::ok);
  EXPECT_EQ(model::forward_kinematics(joints, geometry, pose), model::Status::ok);
  return pose;
}

Cables cables_for(const Joints& joints, const Geometry& geometry = kPrototype) {
  Cables cables;
  EXPECT_EQ(model::cables_from_joints(joints, geometry, cables), model::Status::ok);
  return cables;
}

// Every segment bent by theta in the plane alpha.
Joints uniform_joints(double alpha_rad, double theta_rad, int segments = 4) {
  Joints joints(2 * segments);
  for (int i = 0; i < segments; ++i) {
    joints[2 * i] = alpha_rad;
    joints[2 * i + 1] = theta_rad;
  }
  return joints;
}

Joints mixed_joints() {
  Joints joints(8);
  joints << 0.9, 0.07, -2.4, 0.06, -0.4, 0.12, -2.05, 0.19;
  return joints;
}

std::vector<Cables> workspace_cables(double theta_max_rad, int count, std::uint64_t seed = 3) {
  WorkspaceSampler sampler(kPrototype, theta_max_rad, seed);
  std::vector<Cables> cables;
  for (int i = 0; i < count; ++i) cables.push_back(sampler.next().cables_mm);
  cables.push_back(cables_for(uniform_joints(0.0, 0.0)));
  return cables;
}

bool identical(const Pose& a, const Pose& b) { return a.rotation == b.rotation && a.position_mm == b.position_mm; }

double distance_mm(const Pose& a, const Pose& b) { return (a.position_mm - b.position_mm).norm(); }
double angle_rad(const Pose& a, const Pose& b) { return model::pose_error(a, b).orientation_rad; }

struct Source {
  const char* name;
  std::function<void(SimulatorConfig&)> enable;
  bool is_noise;
};

const std::vector<Source>& sources() {
  static const std::vector<Source> list = {
      {"geometric", [](SimulatorConfig& c) { c.geometric.enabled = true; }, false},
      {"curvature", [](SimulatorConfig& c) { c.curvature.enabled = true; }, false},
      {"compliance", [](SimulatorConfig& c) { c.compliance.enabled = true; }, false},
      {"gravity", [](SimulatorConfig& c) { c.gravity.enabled = true; }, false},
      {"repeatability", [](SimulatorConfig& c) { c.repeatability.enabled = true; }, true},
      {"mocap noise", [](SimulatorConfig& c) { c.mocap_noise.enabled = true; }, true},
  };
  return list;
}

TEST(SimulatedRobot, EverySourceOffIsTheNominalModelExactly) {
  SimulatedRobot robot(kPrototype, SimulatorConfig::nominal_only());
  for (const Cables& cables : workspace_cables(1.5, 100)) {
    const Pose expected = nominal_pose(cables);
    const Measurement m = robot.measure(cables);
    EXPECT_TRUE(identical(robot.true_pose(cables), expected));
    EXPECT_TRUE(identical(m.true_pose, expected));
    EXPECT_TRUE(identical(m.measured_pose, expected));
  }
}

TEST(SimulatedRobot, EverySourceOffReproducesTable1Case2) {
  const Geometry table1 = Geometry::uniform(4, 120.0, 70.0);
  Cables cables(16);
  cables << 118, 123, 124, 115, 124, 115, 118, 121, 110, 117, 125, 123, 124, 105, 112, 128;
  SimulatedRobot robot(table1, SimulatorConfig::nominal_only());
  const Pose pose = robot.true_pose(cables);
  EXPECT_TRUE(identical(pose, nominal_pose(cables, table1)));
  EXPECT_NEAR(pose.position_mm.x(), 19.2070, 1e-4);
  EXPECT_NEAR(pose.position_mm.y(), -6.3962, 1e-4);
  EXPECT_NEAR(pose.position_mm.z(), 478.3811, 1e-4);
}

TEST(SimulatedRobot, EachSourceAloneChangesThePose) {
  const std::vector<Cables> cables = workspace_cables(0.2, 20);
  for (const Source& source : sources()) {
    SCOPED_TRACE(source.name);
    SimulatorConfig config = SimulatorConfig::nominal_only();
    source.enable(config);
    SimulatedRobot robot(kPrototype, config);
    double moved_mm = 0.0;
    for (const Cables& c : cables) {
      const Pose nominal = nominal_pose(c);
      const Measurement m = robot.measure(c);
      if (source.is_noise) {
        // The robot itself is the nominal one; only the report is noisy.
        EXPECT_TRUE(identical(m.true_pose, nominal));
        EXPECT_FALSE(identical(m.measured_pose, nominal));
        moved_mm += distance_mm(m.measured_pose, nominal);
      } else {
        EXPECT_TRUE(identical(m.measured_pose, m.true_pose));
        EXPECT_TRUE(identical(robot.true_pose(c), m.true_pose));
        moved_mm += distance_mm(m.true_pose, nominal);
      }
    }
    EXPECT_GT(moved_mm / cables.size(), 0.3);
  }
}

TEST(SimulatedRobot, TruePoseIsDeterministic) {
  SimulatedRobot robot(kPrototype, SimulatorConfig{});
  const Cables cables = cables_for(mixed_joints());
  const Pose first = robot.true_pose(cables);
  for (int i = 0; i < 5; ++i) {
    EXPECT_TRUE(identical(robot.measure(cables).true_pose, first));
    EXPECT_TRUE(identical(robot.true_pose(cables), first));
  }
}

TEST(SimulatedRobot, SameSeedSameRobotAndSameData) {
  SimulatedRobot a(kPrototype, SimulatorConfig{});
  SimulatedRobot b(kPrototype, SimulatorConfig{});
  for (const Cables& cables : workspace_cables(0.2, 50)) {
    const Measurement ma = a.measure(cables);
    const Measurement mb = b.measure(cables);
    EXPECT_TRUE(identical(ma.true_pose, mb.true_pose));
    EXPECT_TRUE(identical(ma.measured_pose, mb.measured_pose));
  }
}

TEST(SimulatedRobot, DifferentSeedDifferentRobot) {
  SimulatorConfig other;
  other.seed = 2;
  const SimulatedRobot a(kPrototype, SimulatorConfig{});
  const SimulatedRobot b(kPrototype, other);
  EXPECT_NE(a.deviations().segments[0].backbone_length_error_mm, b.deviations().segments[0].backbone_length_error_mm);
  EXPECT_FALSE(identical(a.deviations().base_mount, b.deviations().base_mount));
  for (const Cables& cables : workspace_cables(0.2, 20)) {
    EXPECT_GT(distance_mm(a.true_pose(cables), b.true_pose(cables)), 0.1);
  }
}

// A seed is a robot: switching a source off zeroes its own values and leaves
// the values of every other source as they were.
TEST(SimulatedRobot, SwitchesDoNotReshuffleOtherSources) {
  SimulatorConfig without_geometric;
  without_geometric.geometric.enabled = false;
  SimulatorConfig without_curvature;
  without_curvature.curvature.enabled = false;
  const RobotDeviations all = SimulatedRobot(kPrototype, SimulatorConfig{}).deviations();
  const RobotDeviations no_geometric = SimulatedRobot(kPrototype, without_geometric).deviations();
  const RobotDeviations no_curvature = SimulatedRobot(kPrototype, without_curvature).deviations();
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(no_geometric.segments[i].curvature_gradient, all.segments[i].curvature_gradient);
    EXPECT_EQ(no_geometric.segments[i].anchor_angle_offset_rad, 0.0);
    EXPECT_EQ(no_curvature.segments[i].anchor_angle_offset_rad, all.segments[i].anchor_angle_offset_rad);
    EXPECT_EQ(no_curvature.segments[i].curvature_gradient, 0.0);
  }
  EXPECT_TRUE(identical(no_curvature.base_mount, all.base_mount));
  EXPECT_TRUE(identical(no_geometric.base_mount, Pose::identity()));

  // The per-sample noise too: the mocap error is the same draw whether or not
  // repeatability is on.
  SimulatorConfig mocap_only = SimulatorConfig::nominal_only();
  mocap_only.mocap_noise.enabled = true;
  SimulatorConfig mocap_and_repeatability = mocap_only;
  mocap_and_repeatability.repeatability.enabled = true;
  mocap_and_repeatability.repeatability.bend_sigma_rad = 0.0;
  SimulatedRobot a(kPrototype, mocap_only);
  SimulatedRobot b(kPrototype, mocap_and_repeatability);
  for (const Cables& cables : workspace_cables(0.2, 10)) {
    EXPECT_TRUE(identical(a.measure(cables).measured_pose, b.measure(cables).measured_pose));
  }
}

TEST(SimulatedRobot, GeometricErrorsMatchTheirSigmas) {
  SimulatorConfig config = SimulatorConfig::nominal_only();
  config.geometric.enabled = true;
  double sum_sq_length = 0.0, sum_sq_angle = 0.0;
  constexpr int robots = 500;
  for (int seed = 1; seed <= robots; ++seed) {
    config.seed = static_cast<std::uint64_t>(seed);
    const RobotDeviations d = SimulatedRobot(kPrototype, config).deviations();
    for (int i = 0; i < 4; ++i) {
      sum_sq_length += d.segments[i].backbone_length_error_mm * d.segments[i].backbone_length_error_mm;
      sum_sq_angle += d.segments[i].anchor_angle_offset_rad * d.segments[i].anchor_angle_offset_rad;
    }
  }
  EXPECT_NEAR(std::sqrt(sum_sq_length / (4 * robots)), config.geometric.backbone_length_sigma_mm,
              0.05 * config.geometric.backbone_length_sigma_mm);
  EXPECT_NEAR(std::sqrt(sum_sq_angle / (4 * robots)), config.geometric.anchor_angle_sigma_rad,
              0.05 * config.geometric.anchor_angle_sigma_rad);
}

// The anchor angular offset rotates the bending plane: alpha reads off by
// exactly the drawn angle, theta does not change.
TEST(SimulatedRobot, AnchorOffsetRotatesTheBendingPlane) {
  SimulatorConfig config = SimulatorConfig::nominal_only();
  config.geometric.enabled = true;
  config.geometric.anchor_radius_sigma_mm = 0.0;
  SimulatedRobot robot(kPrototype, config);
  const Joints commanded = mixed_joints();
  const Joints achieved = model::joints_from_bend(robot.achieved_bends(cables_for(commanded)));
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(achieved[2 * i + 1], commanded[2 * i + 1], 1e-12);
    EXPECT_NEAR(std::remainder(achieved[2 * i] - commanded[2 * i], 2.0 * kPi),
                robot.deviations().segments[i].anchor_angle_offset_rad, 1e-9);
  }
}

TEST(SimulatedRobot, ComplianceScalesTheBendByTheCableShare) {
  SimulatorConfig config = SimulatorConfig::nominal_only();
  config.compliance.enabled = true;
  SimulatedRobot robot(kPrototype, config);

  // Straight: the cables hold no bending moment and stretch equally.
  const Cables straight = cables_for(uniform_joints(0.0, 0.0));
  EXPECT_TRUE(identical(robot.true_pose(straight), nominal_pose(straight)));

  const double EI = config.structure.backbone_bending_stiffness_n_mm2;
  const double cable_share = 2.0 * config.structure.cable_stiffness_n_per_mm * 67.0 * 67.0;
  const double retained = cable_share / (EI / 120.0 + cable_share);
  const Joints commanded = mixed_joints();
  const Joints bends = robot.achieved_bends(cables_for(commanded));
  const Joints commanded_bends = model::bend_from_joints(commanded);
  for (int i = 0; i < 8; ++i) EXPECT_NEAR(bends[i], retained * commanded_bends[i], 1e-12);

  // The loss grows with the bend: the position error does too.
  const double small = distance_mm(robot.true_pose(cables_for(uniform_joints(0.5, 0.05))),
                                   nominal_pose(cables_for(uniform_joints(0.5, 0.05))));
  const double large = distance_mm(robot.true_pose(cables_for(uniform_joints(0.5, 0.2))),
                                   nominal_pose(cables_for(uniform_joints(0.5, 0.2))));
  EXPECT_GT(small, 0.0);
  EXPECT_GT(large, 3.0 * small);
}

SimulatorConfig gravity_only(const Eigen::Vector3d& direction) {
  SimulatorConfig config = SimulatorConfig::nominal_only();
  config.gravity.enabled = true;
  config.gravity.direction = direction;
  return config;
}

TEST(SimulatedRobot, GravityDoesNotBendAStraightUprightRobot) {
  SimulatedRobot robot(kPrototype, gravity_only({0.0, 0.0, -1.0}));
  const Cables straight = cables_for(uniform_joints(0.0, 0.0));
  EXPECT_EQ(robot.achieved_bends(straight).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_TRUE(identical(robot.true_pose(straight), nominal_pose(straight)));
}

TEST(SimulatedRobot, GravityBendsABentUprightRobotFurther) {
  SimulatedRobot robot(kPrototype, gravity_only({0.0, 0.0, -1.0}));
  for (const double theta : {0.05, 0.2}) {
    const Joints commanded = uniform_joints(0.7, theta);
    const Joints achieved = model::joints_from_bend(robot.achieved_bends(cables_for(commanded)));
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(achieved[2 * i], 0.7, 1e-12);  // in the bending plane
      EXPECT_GT(achieved[2 * i + 1], theta);     // and further down
    }
  }
  // The moment grows with the lever arm: more bend, more sag.
  const auto sag_rad = [&](double theta) {
    const Joints achieved = model::joints_from_bend(robot.achieved_bends(cables_for(uniform_joints(0.7, theta))));
    return achieved[1] - theta;
  };
  EXPECT_GT(sag_rad(0.2), 3.0 * sag_rad(0.05));
}

TEST(SimulatedRobot, GravitySagsAHorizontalRobotTowardsTheGround) {
  SimulatedRobot robot(kPrototype, gravity_only({-1.0, 0.0, 0.0}));
  const Cables straight = cables_for(uniform_joints(0.0, 0.0));
  const Pose pose = robot.true_pose(straight);
  EXPECT_LT(pose.position_mm.x(), -10.0);
  EXPECT_NEAR(pose.position_mm.y(), 0.0, 1e-9);
  EXPECT_LT(pose.rotation(0, 2), 0.0);  // the end disk faces downwards
  // The moment arm is the horizontal reach: bending the robot up against
  // gravity (alpha = 0 bends towards +x) shortens it, so the first segment
  // sags less than when the robot is straight.
  const double sag_straight = robot.achieved_bends(straight)[0];
  const double sag_up = robot.achieved_bends(cables_for(uniform_joints(0.0, 0.2)))[0] - 0.2;
  EXPECT_LT(sag_straight, 0.0);
  EXPECT_LT(sag_up, 0.0);
  EXPECT_LT(std::abs(sag_up), std::abs(sag_straight));
}

// The equilibrium itself, for one segment carrying only an end platform at its end
// disk: b - b_commanded = M / K with M = m g x_tip in the bending plane.
TEST(SimulatedRobot, GravityEquilibriumBalancesTheMoment) {
  const Geometry one = Geometry::uniform(1, 120.0, 67.0);
  SimulatorConfig config = gravity_only({0.0, 0.0, -1.0});
  config.gravity.segment_mass_kg = 0.0;
  config.gravity.platform_mass_kg = 0.5;
  SimulatedRobot robot(one, config);
  Joints commanded(2);
  commanded << 0.3, 0.25;
  const Joints bend = robot.achieved_bends(cables_for(commanded, one));
  const Pose tip = robot.pose_from_bends(bend);
  const double K = config.structure.backbone_bending_stiffness_n_mm2 / 120.0 +
                   2.0 * config.structure.cable_stiffness_n_per_mm * 67.0 * 67.0;
  const double lateral_mm = tip.position_mm.head<2>().norm();
  const double expected_sag = 0.5 * 9.81 * lateral_mm / K;
  EXPECT_NEAR(bend.norm() - 0.25, expected_sag, 1e-12);
  EXPECT_GT(expected_sag, 1e-3);
}

TEST(SimulatedRobot, CurvatureGradientsAreDrawnPerSegment) {
  SimulatorConfig config = SimulatorConfig::nominal_only();
  config.curvature.enabled = true;
  const RobotDeviations d = SimulatedRobot(kPrototype, config).deviations();
  for (int i = 0; i < 4; ++i) {
    EXPECT_NE(d.segments[i].curvature_gradient, 0.0);
    EXPECT_LT(std::abs(d.segments[i].curvature_gradient - config.curvature.gradient_mean),
              5.0 * config.curvature.gradient_sigma);
  }
  EXPECT_NE(d.segments[0].curvature_gradient, d.segments[1].curvature_gradient);
  // Curvature changes the position only: the bends are those commanded.
  SimulatedRobot robot(kPrototype, config);
  const Joints commanded = mixed_joints();
  const Joints achieved = robot.achieved_bends(cables_for(commanded));
  EXPECT_LE((achieved - model::bend_from_joints(commanded)).cwiseAbs().maxCoeff(), 1e-12);
  const Cables cables = cables_for(commanded);
  EXPECT_LT(angle_rad(robot.true_pose(cables), nominal_pose(cables)), 1e-12);
  EXPECT_GT(distance_mm(robot.true_pose(cables), nominal_pose(cables)), 0.1);
}

TEST(SimulatedRobot, RejectsBadInput) {
  SimulatedRobot robot(kPrototype, SimulatorConfig{});
  EXPECT_THROW(robot.true_pose(Cables::Constant(12, 120.0)), std::invalid_argument);
  Cables cables = Cables::Constant(16, 120.0);
  cables[5] = std::nan("");
  EXPECT_THROW(robot.true_pose(cables), std::invalid_argument);
  cables[5] = -1.0;
  EXPECT_THROW(robot.measure(cables), std::invalid_argument);

  SimulatorConfig config;
  config.mocap_noise.position_sigma_mm = -0.5;
  EXPECT_THROW(SimulatedRobot(kPrototype, config), std::invalid_argument);
  config = SimulatorConfig{};
  config.curvature.gradient_mean = 1.5;
  EXPECT_THROW(SimulatedRobot(kPrototype, config), std::invalid_argument);
  config = SimulatorConfig{};
  config.gravity.direction.setZero();
  EXPECT_THROW(SimulatedRobot(kPrototype, config), std::invalid_argument);
  EXPECT_THROW(SimulatedRobot(Geometry::uniform(0, 120.0, 67.0), SimulatorConfig{}), std::invalid_argument);
  EXPECT_THROW(WorkspaceSampler(kPrototype, 2.0, 1), std::invalid_argument);
}

}  // namespace
}  // namespace cdcr::sim
