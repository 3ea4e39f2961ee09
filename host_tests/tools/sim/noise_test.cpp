// The unlearnable part: the noise floor the simulator reports must follow
// from the configured noise magnitudes.

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/model/chain.hpp>
#include <cdcr/model/units.hpp>

#include "sim/data_collection.hpp"

#include "mean_error_bounds.hpp"

namespace cdcr::sim {
namespace {

using Geometry = model::RobotGeometry<double>;

using model::kDegreesPerRadian;
using model::kPi;
const Geometry kPrototype = Geometry::prototype();
constexpr int kSamples = 5000;

// Mean norm of a d-dimensional isotropic normal with unit sigma.
const double kMeanNorm2d = std::sqrt(kPi / 2.0);
const double kMeanNorm3d = std::sqrt(8.0 / kPi);

TEST(SimulatorNoise, MocapNoiseFloorMatchesItsSigmas) {
  SimulatorConfig config = SimulatorConfig::nominal_only();
  config.mocap_noise.enabled = true;
  config.mocap_noise.position_sigma_mm = 0.5;
  config.mocap_noise.rotation_sigma_rad = 0.2 / kDegreesPerRadian;
  SimulatedRobot robot(kPrototype, config);
  const CollectionSummary summary = summarize(collect(robot, kSamples));
  EXPECT_NEAR(summary.noise_floor.position_mm, 0.5 * kMeanNorm3d, 0.03 * 0.5 * kMeanNorm3d);  // ~0.80 mm
  EXPECT_NEAR(summary.noise_floor.orientation_deg, 0.2 * kMeanNorm3d, 0.03 * 0.2 * kMeanNorm3d);
  // Without systematic errors the initial error is the noise itself.
  EXPECT_DOUBLE_EQ(summary.initial.position_mm, summary.noise_floor.position_mm);
}

// A straight robot, each bend component perturbed by sigma: to first order
// the end disk tilts by the sum of the segments' rotation vectors (2-D normal,
// sigma sqrt(n) per axis) and moves sideways by sum_i b_i L (n - i - 1/2)
// (2-D normal, sigma L sqrt(sum (n - i - 1/2)^2) per axis).
TEST(SimulatorNoise, RepeatabilityFloorMatchesItsSigma) {
  SimulatorConfig config = SimulatorConfig::nominal_only();
  config.repeatability.enabled = true;
  const double sigma = config.repeatability.bend_sigma_rad;
  SimulatedRobot robot(kPrototype, config);
  model::CableVector<double> straight = model::CableVector<double>::Constant(16, 120.0);
  std::vector<model::Pose<double>> truth, measured;
  for (int k = 0; k < kSamples; ++k) {
    const Measurement m = robot.measure(straight);
    truth.push_back(m.true_pose);
    measured.push_back(m.measured_pose);
  }
  const MeanPoseError floor = mean_pose_error(measured, truth);
  const double lever_sq = 3.5 * 3.5 + 2.5 * 2.5 + 1.5 * 1.5 + 0.5 * 0.5;
  const double expected_mm = sigma * 120.0 * std::sqrt(lever_sq) * kMeanNorm2d;
  const double expected_deg = sigma * 2.0 * kMeanNorm2d * kDegreesPerRadian;
  EXPECT_NEAR(floor.position_mm, expected_mm, 0.03 * expected_mm);
  EXPECT_NEAR(floor.orientation_deg, expected_deg, 0.03 * expected_deg);
}

TEST(SimulatorNoise, NoNoiseNoFloor) {
  SimulatorConfig config;
  config.repeatability.enabled = false;
  config.mocap_noise.enabled = false;
  SimulatedRobot robot(kPrototype, config);
  const CollectionSummary summary = summarize(collect(robot, 50));
  EXPECT_EQ(summary.noise_floor.position_mm, 0.0);
  EXPECT_NEAR(summary.noise_floor.orientation_deg, 0.0, 1e-12);  // the angle of R R^T, one rounding off
  EXPECT_GT(summary.initial.position_mm, 10.0);
}

// The default floor is the paper's: repeatability of a few millimetres, on
// top of the motion capture's 0.5 mm.
TEST(SimulatorNoise, DefaultFloorIsAFewMillimetres) {
  SimulatedRobot robot(kPrototype, SimulatorConfig{});
  const CollectionSummary summary = summarize(collect(robot, 750));
  test_types::expect_mean_error_between(summary.noise_floor, 1.0, 4.0, 0.2, 1.0);
}

}  // namespace
}  // namespace cdcr::sim
