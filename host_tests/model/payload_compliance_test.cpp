// The payload's sag (payload_compliance.hpp): the fixed iteration count
// against the converged fixed point, float32 against double, the explicit
// inverse against the forward sag, and the empty model leaving the bends.
//
// The compliance is the simulator's (EI/L + 2 k r^2 = 8e5/120 + 2 * 4 * 67^2
// N mm/rad per segment of the prototype), with gravity across the straight
// robot, a 0.2 kg end platform and a softening of 0.3 per rad; the
// independent robot's identified compliances are within a factor of two.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "cdcr/model/payload_compliance.hpp"

namespace cdcr::model {
namespace {

constexpr double kSimulatorSegmentStiffnessNmmPerRad = 8.0e5 / 120.0 + 2.0 * 4.0 * 67.0 * 67.0;
constexpr double kGravity = 9.81;
// The heaviest payload the identification's data hold.
constexpr double kHeaviestPayloadKg = 1.0;  // and the 0.2 kg platform

PayloadCompliance<double> simulator_compliance(double scale = 1.0) {
  PayloadCompliance<double> c;
  c.segments = kPrototypeSegmentCount;
  c.weighted_gravity = scale * kGravity / kSimulatorSegmentStiffnessNmmPerRad * Vec3<double>(-1.0, 0.2, -0.3).normalized();
  c.ratio = {1.0, 0.8, 1.1, 1.25};
  c.softening_per_rad = 0.3;
  c.unloaded_mass_kg = 0.2;
  return c;
}

// The plain fixed-point iteration, `iterations` passes from the commanded
// shape: the converged reference after enough of them.
JointVector<double> iterated(const JointVector<double>& bends, const RobotGeometry<double>& geometry, double payload_kg,
                             const PayloadCompliance<double>& c, int iterations) {
  const double mass = payload_kg + c.unloaded_mass_kg;
  JointVector<double> current = bends, sag;
  for (int k = 0; k < iterations; ++k) {
    sag_on_shape(current, geometry, mass, c, sag);
    for (int i = 0; i < geometry.segment_count; ++i) {
      current.segment<2>(2 * i) =
          bends.segment<2>(2 * i) + (1.0 + c.softening_per_rad * bends.segment<2>(2 * i).norm()) * sag.segment<2>(2 * i);
    }
  }
  return current;
}

std::vector<JointVector<double>> workspace_bends(int count, double theta_max_rad) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> alpha(-3.14159, 3.14159), theta(0.0, theta_max_rad);
  std::vector<JointVector<double>> bends;
  for (int k = 0; k < count; ++k) {
    JointVector<double> joints(2 * kPrototypeSegmentCount);
    for (int s = 0; s < kPrototypeSegmentCount; ++s) {
      joints[2 * s] = alpha(rng);
      joints[2 * s + 1] = theta(rng);
    }
    bends.push_back(bend_from_joints(joints));
  }
  // The straight robot, where gravity's lever arms are longest.
  bends.push_back(JointVector<double>::Zero(2 * kPrototypeSegmentCount));
  return bends;
}

// Largest bend error and tip position error (mm) of `steps` Newton steps
// against the converged fixed point, over the workspace to its bending limit.
struct Left {
  double bend_rad = 0.0;
  double tip_mm = 0.0;
};
Left left_after(int steps, const PayloadCompliance<double>& c) {
  const auto geometry = RobotGeometry<double>::prototype();
  Left left;
  for (const JointVector<double>& b : workspace_bends(200, geometry.segments[0].theta_max_rad)) {
    const JointVector<double> converged = iterated(b, geometry, kHeaviestPayloadKg, c, 600);
    const JointVector<double> after = sagged_bends_after(steps, b, geometry, kHeaviestPayloadKg, c);
    left.bend_rad = std::max(left.bend_rad, (after - converged).cwiseAbs().maxCoeff());
    left.tip_mm = std::max(left.tip_mm, (forward_kinematics_bend(after, geometry).position_mm -
                                         forward_kinematics_bend(converged, geometry).position_mm)
                                            .norm());
  }
  return left;
}

TEST(PayloadCompliance, TheFixedNewtonStepsReachTheConvergedSag) {
  for (const double scale : {1.0, 2.0}) {
    for (const int n : {1, 2, 3, 4}) {
      const Left left = left_after(n, simulator_compliance(scale));
      std::printf("  compliance x%.0f, %d Newton steps: largest bend error %.1e rad, tip %.1e mm\n", scale, n,
                  left.bend_rad, left.tip_mm);
    }
  }
  // The simulator's compliance: below float32's rounding of a bend of a
  // radian; twice it: a fortieth of the image's fidelity target at the tip.
  const Left measured = left_after(kSagNewtonSteps, simulator_compliance(1.0));
  EXPECT_LT(measured.bend_rad, 6e-8);
  const Left twice = left_after(kSagNewtonSteps, simulator_compliance(2.0));
  EXPECT_LT(twice.tip_mm, 2.5e-4);
}

TEST(PayloadCompliance, TheSagBendsTowardsGravity) {
  const auto geometry = RobotGeometry<double>::prototype();
  const PayloadCompliance<double> c = simulator_compliance();
  const JointVector<double> straight = JointVector<double>::Zero(8);
  const Pose<double> loaded = sagged_pose(straight, geometry, 1.0, c);
  const Vec3<double> moved = loaded.position_mm - forward_kinematics_bend(straight, geometry).position_mm;
  // Tens of millimetres, along gravity's part across the straight robot.
  EXPECT_GT(moved.norm(), 20.0);
  Vec3<double> across = c.weighted_gravity;
  across.z() = 0.0;
  EXPECT_GT(moved.normalized().dot(across.normalized()), 0.95);
}

TEST(PayloadCompliance, FloatFollowsDouble) {
  const auto geometry = RobotGeometry<double>::prototype();
  const auto geometry_f = geometry.cast<float>();
  const PayloadCompliance<double> c = simulator_compliance();
  const PayloadCompliance<float> c_f = c.cast<float>();
  double worst_mm = 0.0;
  for (const JointVector<double>& b : workspace_bends(200, 1.5)) {
    const Pose<double> reference = sagged_pose(b, geometry, 0.8, c);
    const JointVector<float> b_f = b.cast<float>();
    const Pose<float> single = sagged_pose(b_f, geometry_f, 0.8f, c_f);
    worst_mm = std::max(worst_mm, (single.position_mm.cast<double>() - reference.position_mm).norm());
  }
  EXPECT_LT(worst_mm, 1e-3);
}

TEST(PayloadCompliance, CommandedBendsInvertTheSag) {
  const auto geometry = RobotGeometry<double>::prototype();
  for (const double softening : {0.0, 0.3, -0.5}) {
    PayloadCompliance<double> c = simulator_compliance();
    c.softening_per_rad = softening;
    for (const JointVector<double>& b : workspace_bends(100, 1.5)) {
      // The converged fixed point, so the inverse is exact to rounding.
      const JointVector<double> sagged = sagged_bends_after(6, b, geometry, 0.9, c);
      const JointVector<double> back = commanded_bends(sagged, geometry, 0.9, c);
      EXPECT_LT((back - b).cwiseAbs().maxCoeff(), 1e-12) << softening;
    }
  }
}

TEST(PayloadCompliance, AnEmptyModelOrNoLoadLeavesTheBends) {
  const auto geometry = RobotGeometry<double>::prototype();
  const JointVector<double> b = workspace_bends(1, 1.0).front();
  EXPECT_EQ(sagged_bends(b, geometry, 1.0, PayloadCompliance<double>{}), b);
  EXPECT_EQ(commanded_bends(b, geometry, 1.0, PayloadCompliance<double>{}), b);
  PayloadCompliance<double> c = simulator_compliance();
  c.unloaded_mass_kg = 0.0;
  EXPECT_EQ(sagged_bends(b, geometry, 0.0, c), b);
  EXPECT_NE(sagged_bends(b, geometry, 0.1, c), b);
}

TEST(PayloadCompliance, SofteningPlausibility) {
  EXPECT_TRUE(plausible_softening(0.0));
  EXPECT_TRUE(plausible_softening(-0.6));
  EXPECT_FALSE(plausible_softening(-0.64));
}

}  // namespace
}  // namespace cdcr::model
