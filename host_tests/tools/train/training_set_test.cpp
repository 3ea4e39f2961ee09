// The GP's training targets, the tip error twists of eq. (18), against cases
// worked out by hand: measured poses made from the nominal ones by a motion
// whose twist is known in closed form. Nothing here calls the library's
// exponential or logarithm to make the expected values.
#include <cmath>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "cdcr/model/chain.hpp"
#include "train/training_set.hpp"

namespace cdcr::training {
namespace {

using model::Pose;

// Four samples of the prototype, each segment bent (the nominal tip
// orientations are far from the identity, so a twist taken in the tip's
// frame instead of the base's would differ).
dataset::Dataset bent_samples(const model::RobotGeometry<double>& geometry) {
  dataset::Dataset data;
  data.segment_count = geometry.segment_count;
  data.has_poses = true;
  const int samples = 4;
  data.cables_mm.resize(samples, 4 * geometry.segment_count);
  for (int k = 0; k < samples; ++k) {
    model::JointVector<double> joints(2 * geometry.segment_count);
    for (int i = 0; i < geometry.segment_count; ++i) {
      joints[2 * i] = 0.7 * double(k + 1) + 1.3 * double(i);   // alpha
      joints[2 * i + 1] = 0.05 + 0.04 * double((k + i) % 4);   // theta
    }
    model::CableVector<double> cables;
    EXPECT_EQ(model::cables_from_joints(joints, geometry, cables), model::Status::ok);
    data.cables_mm.row(k) = cables.transpose();
  }
  return data;
}

Pose<double> nominal_pose(const dataset::Dataset& data, int k, const model::RobotGeometry<double>& geometry) {
  model::JointVector<double> joints;
  EXPECT_EQ(model::joints_from_cables(model::CableVector<double>(data.cables_mm.row(k).transpose()), geometry, joints),
            model::Status::ok);
  return model::forward_kinematics_bend(model::bend_from_joints(joints), geometry);
}

TEST(TrainingSet, TranslatedMeasurementsGiveThePureTranslationTwist) {
  const auto geometry = model::RobotGeometry<double>::prototype();
  dataset::Dataset data = bent_samples(geometry);
  const Eigen::Vector3d offset_mm(1.5, -0.8, 2.25);
  for (int k = 0; k < data.sample_count(); ++k) {
    Pose<double> measured = nominal_pose(data, k, geometry);
    measured.position_mm += offset_mm;
    data.poses.push_back(measured);
  }
  const TrainingSet set = make_training_set(data, geometry, model::InputEncoding::bend_vector);
  ASSERT_EQ(set.size(), data.sample_count());
  for (int k = 0; k < set.size(); ++k) {
    // T_m T_n^-1 is the translation by the offset: twist (offset, 0).
    EXPECT_LT((set.error_twists.row(k).head<3>().transpose() - offset_mm).norm(), 1e-9) << "sample " << k;
    EXPECT_LT(set.error_twists.row(k).tail<3>().norm(), 1e-12) << "sample " << k;
  }
}

TEST(TrainingSet, ScrewMotionAboutAnOffsetAxisGivesItsTwist) {
  const auto geometry = model::RobotGeometry<double>::prototype();
  dataset::Dataset data = bent_samples(geometry);
  // A rotation by phi about the axis through c along u, with no slide: the
  // twist is (v, omega) = (-omega x c, phi u), and the motion maps p to
  // R (p - c) + c.
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  const double phi = 0.02;  // rad, about the size of the robot's errors
  const Eigen::Vector3d centre(40.0, -25.0, 300.0);
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(phi, axis).toRotationMatrix();
  const Eigen::Vector3d omega = phi * axis;
  const Eigen::Vector3d v = -omega.cross(centre);
  for (int k = 0; k < data.sample_count(); ++k) {
    const Pose<double> nominal = nominal_pose(data, k, geometry);
    Pose<double> measured;
    measured.rotation = rotation * nominal.rotation;
    measured.position_mm = rotation * (nominal.position_mm - centre) + centre;
    data.poses.push_back(measured);
  }
  const TrainingSet set = make_training_set(data, geometry, model::InputEncoding::bend_vector);
  for (int k = 0; k < set.size(); ++k) {
    EXPECT_LT((set.error_twists.row(k).head<3>().transpose() - v).norm(), 1e-9)
        << "sample " << k << ": v " << set.error_twists.row(k).head<3>() << ", expected " << v.transpose();
    EXPECT_LT((set.error_twists.row(k).tail<3>().transpose() - omega).norm(), 1e-12)
        << "sample " << k << ": omega " << set.error_twists.row(k).tail<3>() << ", expected " << omega.transpose();
  }
}

TEST(TrainingSet, InputsAreTheNominalInverseOfTheCommandedCables) {
  const auto geometry = model::RobotGeometry<double>::prototype();
  dataset::Dataset data = bent_samples(geometry);
  for (int k = 0; k < data.sample_count(); ++k) data.poses.push_back(nominal_pose(data, k, geometry));
  const TrainingSet set = make_training_set(data, geometry, model::InputEncoding::bend_vector);
  for (int k = 0; k < set.size(); ++k) {
    // bend = theta (cos alpha, sin alpha) per segment, from the joints the
    // samples were made with.
    for (int i = 0; i < geometry.segment_count; ++i) {
      const double alpha = 0.7 * double(k + 1) + 1.3 * double(i);
      const double theta = 0.05 + 0.04 * double((k + i) % 4);
      EXPECT_NEAR(set.inputs(k, 2 * i), theta * std::cos(alpha), 1e-9) << "sample " << k << " segment " << i;
      EXPECT_NEAR(set.inputs(k, 2 * i + 1), theta * std::sin(alpha), 1e-9) << "sample " << k << " segment " << i;
    }
    EXPECT_LT(set.error_twists.row(k).norm(), 1e-9);
  }
}

}  // namespace
}  // namespace cdcr::training
