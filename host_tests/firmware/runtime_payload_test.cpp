// The payload on the bus: a model with the payload input runs at the image's
// default until a PAYLOAD frame arrives, then at the received payload, in the
// forward path and in IK alike; a frame beyond the signal's range (or a NaN
// given to the runtime directly) is refused with FaultCode::payload_invalid
// and the previous payload stays in use.

#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "runtime_test_fixture.hpp"
#include "train/evaluation.hpp"

namespace cdcr::firmware {
namespace {

namespace protocol = firmware::protocol;
using test_support::RuntimeTest;

training::TrainedModel payload_model() {
  test_support::SyntheticModelOptions options;
  options.training_points = 8;
  options.payload_input = true;
  options.position_output_factor = 0.1;
  options.rotation_output_factor = 0.001;
  return test_support::synthetic_trained_model(options);
}

class RuntimePayloadTest : public RuntimeTest {
 protected:
  void SetUp() override {
    image = exporting::write_image(payload_model());
    ASSERT_EQ(model::parse_image(image.data(), image.size(), view), model::ImageStatus::ok);
    boot(image);
    ASSERT_EQ(runtime->state(), RuntimeState::run);
    const hal::CanFilter host_filters[] = {protocol::kStatusFrames, protocol::kIkReportFrames,
                                           protocol::kCableSetpointFrames};
    platform->host_node.set_filters(host_filters, 3);
  }

  // The firmware's forward path (as cdcr eval runs it) at these cables and payload.
  model::Pose<double> expected_pose(const Cables& cables_mm, double payload_kg) const {
    const Eigen::MatrixXd cables = cables_mm.cast<double>().transpose();
    return training::firmware_poses(view, cables, training::FirmwareAccumulator::float64,
                                    Eigen::VectorXd::Constant(1, payload_kg))
        .front();
  }

  // The drives' cables as the runtime receives them (0.01 mm steps).
  Cables received_cables() const {
    Cables cables = drives->cables_mm().cast<float>();
    for (Eigen::Index i = 0; i < cables.size(); ++i) {
      cables[i] = static_cast<float>(protocol::cable_length_as_transmitted(drives->cables_mm()[i]));
    }
    return cables;
  }

  void send_payload_raw(std::int64_t raw, std::uint8_t dlc = 2) {
    hal::CanFrame frame;
    ASSERT_TRUE(protocol::encode(protocol::Payload{0.0}, frame));
    protocol::write_raw(frame, protocol::payload::kPayload, raw);
    frame.dlc = dlc;
    send(frame);
  }

  std::vector<std::uint8_t> image;
  model::ImageView view{};
};

TEST_F(RuntimePayloadTest, TheImagesDefaultUntilAPayloadArrivesThenTheReceivedOne) {
  cycles(3);
  EXPECT_FALSE(runtime->payload_received());
  EXPECT_EQ(runtime->payload_kg(), 0.375f);
  const Cables cables = received_cables();
  const model::Pose<double> at_default = runtime->latest_pose().pose.cast<double>();
  EXPECT_LT((at_default.position_mm - expected_pose(cables, 0.375).position_mm).norm(), 1e-4);

  send_frame(protocol::Payload{0.8});
  cycles(2);
  EXPECT_TRUE(runtime->payload_received());
  EXPECT_EQ(runtime->payload_kg(), 0.8f);
  const model::Pose<double> loaded = runtime->latest_pose().pose.cast<double>();
  EXPECT_LT((loaded.position_mm - expected_pose(cables, 0.8).position_mm).norm(), 1e-4);
  // The payload moved the compensated tip.
  EXPECT_GT((loaded.position_mm - at_default.position_mm).norm(), 1e-3);
  EXPECT_EQ(runtime->statistics().rejected_frames, 0u);
}

TEST_F(RuntimePayloadTest, AnOutOfRangeOrMalformedPayloadIsRefusedAndThePreviousOneKept) {
  send_frame(protocol::Payload{0.25});
  cycles(2);
  ASSERT_EQ(runtime->payload_kg(), 0.25f);
  const model::Pose<double> before = runtime->latest_pose().pose.cast<double>();

  // 60 kg: beyond the signal's 50.
  send_payload_raw(60000);
  cycles(1);
  EXPECT_EQ(runtime->payload_kg(), 0.25f);
  EXPECT_EQ(runtime->last_event(), FaultCode::payload_invalid);
  EXPECT_EQ(runtime->statistics().rejected_frames, 1u);
  EXPECT_EQ(runtime->latest_pose().pose.position_mm.cast<double>(), before.position_mm);
  // A refused payload is no reason to stop: the runtime stays in RUN.
  cycles(10);
  EXPECT_EQ(runtime->state(), RuntimeState::run);

  // A frame of the wrong length.
  send_payload_raw(500, 3);
  cycles(1);
  EXPECT_EQ(runtime->payload_kg(), 0.25f);
  EXPECT_EQ(runtime->statistics().rejected_frames, 2u);

  // Through the runtime's own call: NaN, negative, beyond the range.
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), -0.1f, 50.5f,
                          std::numeric_limits<float>::infinity()}) {
    EXPECT_FALSE(runtime->set_payload_kg(bad)) << bad;
    EXPECT_EQ(runtime->payload_kg(), 0.25f);
    EXPECT_EQ(runtime->last_event(), FaultCode::payload_invalid);
  }
  EXPECT_TRUE(runtime->set_payload_kg(50.0f));
  EXPECT_EQ(runtime->payload_kg(), 50.0f);
}

TEST_F(RuntimePayloadTest, TheStatusFrameReportsARefusedPayload) {
  cycles(5);
  host_frames();
  send_payload_raw(65535);
  bool reported = false;
  for (int i = 0; i < 10 && !reported; ++i) {
    cycles(1);
    protocol::Status status;
    if (last_of(host_frames(), status)) reported = status.fault == FaultCode::payload_invalid;
  }
  EXPECT_TRUE(reported);
}

// The fitted input range includes the payload's: a payload the frame can
// carry but the model never saw flags the pose as outside the range.
TEST_F(RuntimePayloadTest, APayloadBeyondTheFittedRangeIsOutsideIt) {
  // The drives' bend within the model's fitted bend range.
  cycles(3);
  send_frame(protocol::Payload{0.5});
  cycles(2);
  ASSERT_EQ(runtime->payload_kg(), 0.5f);
  EXPECT_FALSE(runtime->latest_pose().outside_range);
  send_frame(protocol::Payload{5.0});
  cycles(2);
  ASSERT_EQ(runtime->payload_kg(), 5.0f);
  EXPECT_TRUE(runtime->latest_pose().outside_range);
  EXPECT_TRUE(runtime->extrapolating());
  send_frame(protocol::Payload{0.5});
  cycles(2);
  EXPECT_FALSE(runtime->latest_pose().outside_range);
}

// IK solves the compensated model at the current payload: the setpoints it
// publishes put the compensated tip on the target at that payload, and
// away from it at the default.
TEST_F(RuntimePayloadTest, InverseKinematicsUsesTheCurrentPayload) {
  send_frame(protocol::Payload{0.9});
  cycles(3);
  ASSERT_EQ(runtime->payload_kg(), 0.9f);
  const model::Vec3<double> target = runtime->latest_pose().pose.position_mm.cast<double>() +
                                     model::Vec3<double>(3.0, -2.0, 0.0);
  send_position_target(target.x(), target.y(), target.z(), 7);
  cycles_until_ik_done();
  protocol::IkReport report;
  ASSERT_TRUE(last_ik_report(report));
  ASSERT_EQ(report.outcome, protocol::IkOutcome::converged);
  ASSERT_TRUE(runtime->has_setpoints());
  const Cables setpoints = runtime->setpoints_mm();
  const double at_payload = (expected_pose(setpoints, 0.9).position_mm - target).norm();
  const double at_default = (expected_pose(setpoints, 0.375).position_mm - target).norm();
  std::printf("IK at 0.9 kg: residual %.4f mm at 0.9 kg, %.4f mm at the default 0.375 kg\n", at_payload, at_default);
  EXPECT_LT(at_payload, 0.05);
  EXPECT_GT(at_default, 4 * at_payload + 0.02);
}

}  // namespace
}  // namespace cdcr::firmware
