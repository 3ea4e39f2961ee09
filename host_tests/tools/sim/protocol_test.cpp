// The paper's protocol on the default simulated robot: 750 random samples of
// the prototype must show Table 2's initial error (53.2 mm, 11.4 deg) in
// order of magnitude, and the error must be a smooth function of the joint
// variables, or no GP could learn it.

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/model/chain.hpp>
#include <cdcr/model/compensation.hpp>

#include "sim/data_collection.hpp"

#include "mean_error_bounds.hpp"

namespace cdcr::sim {
namespace {

using Geometry = model::RobotGeometry<double>;
const Geometry kPrototype = Geometry::prototype();

TEST(SimulatorProtocol, DefaultRobotsShowTable2sInitialError) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    SimulatorConfig config;
    config.seed = seed;
    SimulatedRobot robot(kPrototype, config);
    const CollectionSummary summary = summarize(collect(robot, 750));
    SCOPED_TRACE(testing::Message() << "seed " << seed << ": " << summary.initial.position_mm << " mm, "
                                    << summary.initial.orientation_deg << " deg");
    EXPECT_EQ(summary.samples, 750);
    test_types::expect_mean_error_between(summary.initial, 35.0, 70.0, 7.0, 15.0);
  }
}

TEST(SimulatorProtocol, SamplesFollowThePapersProtocol) {
  SimulatorConfig config;
  SimulatedRobot robot(kPrototype, config);
  const std::vector<CollectedSample> samples = collect(robot, 2000);
  double theta_sum = 0.0;
  double alpha_min = 0.0, alpha_max = 0.0;
  for (const CollectedSample& s : samples) {
    model::CableVector<double> expected;
    ASSERT_EQ(model::cables_from_joints(s.joints, kPrototype, expected), model::Status::ok);
    EXPECT_EQ(s.cables_mm, expected);  // commanded through the nominal inverse
    for (int i = 0; i < 4; ++i) {
      const double alpha = s.joints[2 * i];
      const double theta = s.joints[2 * i + 1];
      EXPECT_GE(theta, 0.0);
      EXPECT_LE(theta, config.workspace_theta_max_rad);
      theta_sum += theta;
      alpha_min = std::min(alpha_min, alpha);
      alpha_max = std::max(alpha_max, alpha);
    }
  }
  // theta uniform in [0, theta_max]: its mean is theta_max / 2.
  EXPECT_NEAR(theta_sum / (4.0 * samples.size()), config.workspace_theta_max_rad / 2.0,
              0.02 * config.workspace_theta_max_rad);
  EXPECT_LT(alpha_min, -3.0);
  EXPECT_GT(alpha_max, 3.0);
}

TEST(SimulatorProtocol, SameSeedSameDataset) {
  SimulatedRobot a(kPrototype, SimulatorConfig{});
  SimulatedRobot b(kPrototype, SimulatorConfig{});
  const std::vector<CollectedSample> da = collect(a, 100);
  const std::vector<CollectedSample> db = collect(b, 100);
  for (std::size_t i = 0; i < da.size(); ++i) {
    EXPECT_EQ(da[i].cables_mm, db[i].cables_mm);
    EXPECT_EQ(da[i].measurement.measured_pose.position_mm, db[i].measurement.measured_pose.position_mm);
    EXPECT_EQ(da[i].measurement.measured_pose.rotation, db[i].measurement.measured_pose.rotation);
  }
}

// The systematic error twist (eq. 18) along a line through bend space that
// crosses theta = 0 for every segment: its second differences must scale as
// h^2 everywhere. A kink or a jump (a clamp, a switch between branches, alpha
// wrapping) would show up as a second difference of order h or 1.
TEST(SimulatorProtocol, ErrorIsSmoothInTheJointVariables) {
  const SimulatedRobot robot(kPrototype, SimulatorConfig{});
  model::JointVector<double> start(8), direction(8);
  // Segment i passes through b = 0 at t = 0.15, 0.1, 0.2 and 0.25.
  direction << 1.0, -0.6, -0.8, 0.3, 0.7, 0.9, -0.5, -0.75;
  start << -0.15 * direction.segment<2>(0), -0.1 * direction.segment<2>(2), -0.2 * direction.segment<2>(4),
      -0.25 * direction.segment<2>(6);
  const auto error_twist = [&](double t) {
    const model::JointVector<double> bend = start + t * direction;
    model::CableVector<double> cables;
    EXPECT_EQ(model::cables_from_joints(model::joints_from_bend(bend), kPrototype, cables), model::Status::ok);
    return model::tip_error_twist(robot.true_pose(cables), model::forward_kinematics_bend(bend, kPrototype));
  };
  const double h = 1e-3;
  double worst = 0.0;
  for (double t = 0.0; t <= 0.3; t += h) {
    const model::Twist<double> second = error_twist(t + h) - 2.0 * error_twist(t) + error_twist(t - h);
    worst = std::max(worst, second.cwiseAbs().maxCoeff() / (h * h));
  }
  // mm (or rad) per rad^2 of bend: a smooth error of a few tens of mm over
  // bends of a few tenths of a radian.
  EXPECT_LT(worst, 2000.0);
}

}  // namespace
}  // namespace cdcr::sim
