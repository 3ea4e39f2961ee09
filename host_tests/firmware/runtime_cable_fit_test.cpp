// A model with the cable-fit encoding on the board (model/cable_fit.hpp):
// the forward path reads the residuals from the cables the drives report,
// as the trainer's evaluation does, and IK solves with the residuals last
// measured held (the bend moves, what the cables do beyond it stays).

#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "cdcr/model/cable_fit.hpp"
#include "cdcr/model/compensation.hpp"
#include "runtime_test_fixture.hpp"
#include "train/evaluation.hpp"

namespace cdcr::firmware {
namespace {

using test_support::RuntimeTest;

class RuntimeCableFitTest : public RuntimeTest {
 protected:
  void SetUp() override {
    test_support::SyntheticModelOptions options;
    options.training_points = 8;
    options.cable_residuals = true;
    options.position_output_factor = 0.1;
    options.rotation_output_factor = 0.001;
    image = exporting::write_image(test_support::synthetic_trained_model(options));
    ASSERT_EQ(model::parse_image(image.data(), image.size(), view), model::ImageStatus::ok);
    ASSERT_EQ(view.encoding, model::InputEncoding::bend_vector_cable_fit);
    boot(image);
    ASSERT_EQ(runtime->state(), RuntimeState::run);
    // Drives whose cables pull against each other: 0.3 mm of imbalance on
    // the first segment, 0.8 mm slack in common on the second.
    consistent = test_support::bent_cables(runtime->geometry());
    measured = consistent;
    measured.segment<4>(0) += model::Vec4<double>(0.3, -0.3, 0.3, -0.3);
    measured.segment<4>(4) += model::Vec4<double>::Constant(-0.8);
    drives = std::make_unique<sim::SimulatedCableDrives>(platform->drives_node, measured, 50.0);
  }

  // The firmware's forward path (as cdcr eval runs it) at these cables.
  model::Pose<double> expected_pose(const model::CableVector<double, kMaxSegments>& cables_mm) const {
    const Eigen::MatrixXd cables = cables_mm.transpose();
    return training::firmware_poses(view, cables, training::FirmwareAccumulator::float64).front();
  }

  // The compensated tip at a bend with the given residuals held.
  model::Vec3<double> tip_with(const Joints& bend, const model::CableResiduals<Scalar, kMaxSegments>& residuals) const {
    model::GpCorrection<double> correction;
    EXPECT_EQ(correction.bind(view), model::Status::ok);
    model::RobotGeometry<double> g;
    EXPECT_EQ(model::geometry_from_image(view, g), model::Status::ok);
    const model::JointVector<double> b = bend.cast<double>();
    const model::Pose<double> nominal = model::forward_kinematics_bend(b, g);
    return model::compensate(correction.predict(b, residuals.cast<double>()), nominal).position_mm;
  }

  std::vector<std::uint8_t> image;
  model::ImageView view{};
  model::CableVector<double, kMaxSegments> consistent, measured;
};

TEST_F(RuntimeCableFitTest, TheForwardPathReadsTheResidualsFromTheCables) {
  cycles(3);
  ASSERT_TRUE(runtime->has_pose());
  const PoseEstimate& estimate = runtime->latest_pose();
  ASSERT_EQ(estimate.cable_residuals.size(), 4);
  EXPECT_NEAR(estimate.cable_residuals[1], 0.6, 1e-3);   // the first segment's imbalance
  EXPECT_NEAR(estimate.cable_residuals[2], -0.8, 1e-3);  // the second's common mode
  // The cables as the runtime receives them (0.01 mm steps).
  model::CableVector<double, kMaxSegments> received = measured;
  for (Eigen::Index i = 0; i < received.size(); ++i) received[i] = protocol::cable_length_as_transmitted(measured[i]);
  const model::Vec3<double> tip = estimate.pose.position_mm.cast<double>();
  EXPECT_LT((tip - expected_pose(received).position_mm).norm(), 1e-4);
  // The same bend without the residuals is another pose.
  EXPECT_GT((tip - expected_pose(consistent).position_mm).norm(), 1e-2);
}

TEST_F(RuntimeCableFitTest, InverseKinematicsHoldsTheResidualsLastMeasured) {
  cycles(3);
  const model::CableResiduals<Scalar, kMaxSegments> held = runtime->latest_pose().cable_residuals;
  const model::Vec3<double> target =
      runtime->latest_pose().pose.position_mm.cast<double>() + model::Vec3<double>(2.0, -1.5, 0.0);
  send_position_target(target.x(), target.y(), target.z(), 3);
  cycles_until_ik_done();
  protocol::IkReport report;
  ASSERT_TRUE(last_ik_report(report));
  ASSERT_EQ(report.outcome, protocol::IkOutcome::converged);
  Joints solution;
  ASSERT_EQ(model::joints_from_cables(runtime->setpoints_mm(), runtime->geometry(), solution), model::Status::ok);
  const Joints bend = model::bend_from_joints(solution);
  model::CableResiduals<Scalar, kMaxSegments> none = held;
  none.setZero();
  const double with_held = (tip_with(bend, held) - target).norm();
  const double without = (tip_with(bend, none) - target).norm();
  std::printf("IK with the residuals held: %.4f mm from the target; %.4f mm were they zero\n", with_held, without);
  EXPECT_LT(with_held, 0.05);
  EXPECT_GT(without, 5.0 * with_held + 0.01);
}

}  // namespace
}  // namespace cdcr::firmware
