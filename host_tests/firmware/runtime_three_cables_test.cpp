// A robot of three cables a segment on the board: the image's cables block
// gives the runtime its geometry, CABLE_FEEDBACK carries each segment's
// three lengths (L4 not available), the pose is the trainer's evaluation of
// the same cables, and IK's setpoints go out three a segment. A four-cable
// segment whose L4 is missing is refused as before.

#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "runtime_test_fixture.hpp"
#include "train/evaluation.hpp"

namespace cdcr::firmware {
namespace {

using test_support::RuntimeTest;

class RuntimeThreeCablesTest : public RuntimeTest {
 protected:
  void SetUp() override {
    test_support::SyntheticModelOptions options;
    options.training_points = 8;
    options.cables_per_segment = 3;
    options.cable_residuals = true;
    options.position_output_factor = 0.1;
    options.rotation_output_factor = 0.001;
    image = exporting::write_image(test_support::synthetic_trained_model(options));
    ASSERT_EQ(model::parse_image(image.data(), image.size(), view), model::ImageStatus::ok);
    boot(image);
    ASSERT_EQ(runtime->state(), RuntimeState::run);
  }

  std::vector<std::uint8_t> image;
  model::ImageView view{};
};

TEST_F(RuntimeThreeCablesTest, ThePoseIsTheTrainersAtTheCablesTheDrivesReport) {
  ASSERT_EQ(runtime->geometry().cable_count(), 6);
  EXPECT_EQ(runtime->geometry().segments[1].cables.count, 3);
  cycles(3);
  ASSERT_TRUE(runtime->has_pose());
  EXPECT_EQ(runtime->statistics().rejected_frames, 0u);
  model::CableVector<double, kMaxSegments> received = drives->cables_mm();
  ASSERT_EQ(received.size(), 6);
  for (Eigen::Index i = 0; i < received.size(); ++i) received[i] = protocol::cable_length_as_transmitted(received[i]);
  const Eigen::MatrixXd rows = received.transpose();
  const model::Pose<double> expected =
      training::firmware_poses(view, rows, training::FirmwareAccumulator::float64).front();
  const model::Vec3<double> tip = runtime->latest_pose().pose.position_mm.cast<double>();
  EXPECT_LT((tip - expected.position_mm).norm(), 1e-4);
}

TEST_F(RuntimeThreeCablesTest, SetpointsGoOutThreeASegment) {
  cycles(3);
  const model::Vec3<double> target =
      runtime->latest_pose().pose.position_mm.cast<double>() + model::Vec3<double>(1.5, -1.0, 0.0);
  send_position_target(target.x(), target.y(), target.z(), 4);
  cycles_until_ik_done();
  protocol::IkReport report;
  ASSERT_TRUE(last_ik_report(report));
  ASSERT_EQ(report.outcome, protocol::IkOutcome::converged);
  ASSERT_EQ(runtime->setpoints_mm().size(), 6);
  // The drives took every segment's frame (L4 not available) and hold the
  // runtime's setpoints.
  cycles(1);
  EXPECT_GE(drives->setpoint_frames(), 2u);
  EXPECT_EQ(drives->rejected_frames(), 0u);
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(drives->setpoints_mm()[i], runtime->setpoints_mm()[i], 0.006) << "cable " << i;
  }
}

// A robot of the paper's four cables: a feedback frame without L4 is a
// malformed frame, as a frame with any length missing always was.
TEST(RuntimeFourCables, AFeedbackFrameWithoutL4IsRefused) {
  test_support::SimulatedPlatform platform(exporting::write_image(test_support::synthetic_trained_model()));
  Runtime runtime(platform.hal, Geometry::uniform(2, 120.0f, 67.0f));
  runtime.init();
  ASSERT_EQ(runtime.geometry().cable_count(), 8);
  hal::CanFrame frame;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  ASSERT_TRUE(protocol::encode(protocol::CableFeedback{0, {120, 120, 120, nan}}, frame));
  ASSERT_EQ(platform.host_node.send(frame), hal::CanStatus::ok);
  runtime.run_cycle(platform.timer.wait_next());
  EXPECT_EQ(runtime.statistics().rejected_frames, 1u);
}

}  // namespace
}  // namespace cdcr::firmware
