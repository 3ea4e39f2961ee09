// Geometry calibration against a robot whose geometry is known: poses made
// by the nominal model with other segment lengths and anchor radii. The
// calibration starts from the design values and must find the true ones,
// leaving no error; rows too few to identify them are refused.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "cdcr/model/chain.hpp"
#include "train/calibration.hpp"

#include "../../support/random_joints.hpp"

namespace cdcr::training {
namespace {

// Commanded cables from random joints through the design geometry, as
// `cdcr simulate` commands them; the poses are where `truth` takes them.
dataset::Dataset robot_with(const model::RobotGeometry<double>& design, const model::RobotGeometry<double>& truth,
                            int samples) {
  dataset::Dataset data;
  data.segment_count = design.segment_count;
  data.has_poses = true;
  data.cables_mm.resize(samples, 4 * design.segment_count);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> alpha(-3.1, 3.1);
  std::uniform_real_distribution<double> theta(0.02, 0.4);
  for (int k = 0; k < samples; ++k) {
    const model::JointVector<double> joints = test_support::random_joints(design.segment_count, rng, alpha, theta);
    model::CableVector<double> cables;
    EXPECT_EQ(model::cables_from_joints(joints, design, cables), model::Status::ok);
    data.cables_mm.row(k) = cables.transpose();
    model::JointVector<double> achieved;
    EXPECT_EQ(model::joints_from_cables(cables, truth, achieved), model::Status::ok);
    data.poses.push_back(model::forward_kinematics_bend(model::bend_from_joints(achieved), truth));
  }
  return data;
}

TEST(GeometryCalibration, FindsTheSegmentLengthsAndRadiiOfTheRobot) {
  const auto design = model::RobotGeometry<double>::prototype();
  model::RobotGeometry<double> truth = design;
  const double length_ratio[] = {1.03, 0.98, 1.01, 0.96};
  const double radius_ratio[] = {1.12, 1.08, 0.95, 1.15};  // cable stretch looks like a larger radius
  for (int s = 0; s < 4; ++s) {
    truth.segments[s].backbone_length_mm *= length_ratio[s];
    truth.segments[s].anchor_radius_mm *= radius_ratio[s];
  }
  const dataset::Dataset data = robot_with(design, truth, 120);
  const TrainingSet set = make_training_set(data, design, model::InputEncoding::bend_vector);
  const Calibration c = calibrate_geometry(set, design);
  EXPECT_GT(c.before.position_mm, 5.0);
  EXPECT_LT(c.after.position_mm, 1e-5);
  EXPECT_LT(c.after.orientation_deg, 1e-6);
  for (int s = 0; s < 4; ++s) {
    EXPECT_NEAR(c.geometry.segments[s].backbone_length_mm, truth.segments[s].backbone_length_mm, 1e-5) << s;
    EXPECT_NEAR(c.geometry.segments[s].anchor_radius_mm, truth.segments[s].anchor_radius_mm, 1e-5) << s;
    EXPECT_EQ(c.geometry.segments[s].theta_max_rad, design.segments[s].theta_max_rad);
  }
}

TEST(GeometryCalibration, TheDesignRobotStaysAsItIs) {
  const auto design = model::RobotGeometry<double>::prototype();
  const TrainingSet set = make_training_set(robot_with(design, design, 40), design, model::InputEncoding::bend_vector);
  const Calibration c = calibrate_geometry(set, design);
  for (int s = 0; s < 4; ++s) {
    EXPECT_NEAR(c.geometry.segments[s].backbone_length_mm, design.segments[s].backbone_length_mm, 1e-9);
    EXPECT_NEAR(c.geometry.segments[s].anchor_radius_mm, design.segments[s].anchor_radius_mm, 1e-9);
  }
}

TEST(GeometryCalibration, TooFewRowsAreRefused) {
  const auto design = model::RobotGeometry<double>::prototype();
  const TrainingSet set = make_training_set(robot_with(design, design, 15), design, model::InputEncoding::bend_vector);
  EXPECT_THROW(calibrate_geometry(set, design), std::invalid_argument);
}

}  // namespace
}  // namespace cdcr::training
