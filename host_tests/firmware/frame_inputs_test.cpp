// The bus's inputs on their own: frames handed straight to a FrameInputs of
// the test's (not the runtime's), which passes what decodes to a booted
// runtime's direct calls and rejects the rest with the fault each frame
// type calls for. A target in parts is solved only with every part its
// mode needs.

#include <gtest/gtest.h>

#include <cdcr/firmware/frame_inputs.hpp>
#include <cdcr/firmware/runtime.hpp>

#include "runtime_test_fixture.hpp"

namespace cdcr::firmware {
namespace {

namespace protocol = firmware::protocol;

template <typename Message>
hal::CanFrame frame_of(const Message& message) {
  hal::CanFrame frame;
  protocol::encode(message, frame);
  return frame;
}

hal::CanFrame position_xy(double x_mm, double y_mm) { return frame_of(protocol::TargetPositionXy{x_mm, y_mm}); }

hal::CanFrame commit(std::uint8_t sequence, protocol::TargetMode mode = protocol::TargetMode::position) {
  protocol::TargetPositionZ z;
  z.z_mm = 150.0;
  z.mode = mode;
  z.sequence = sequence;
  return frame_of(z);
}

// The frame without its data: it no longer decodes.
hal::CanFrame truncated(hal::CanFrame frame) {
  frame.dlc = 0;
  return frame;
}

class FrameInputsTest : public test_support::RuntimeTest {
 protected:
  void SetUp() override {
    boot(test_support::small_image());
    ASSERT_EQ(runtime->state(), RuntimeState::run);
  }

  std::uint32_t rejected() const { return runtime->statistics().rejected_frames; }
  std::uint32_t targets() const { return runtime->statistics().targets_received; }
  // The target with `sequence` was refused as malformed.
  void expect_refused(std::uint8_t sequence) {
    EXPECT_EQ(runtime->last_ik_report().sequence, sequence);
    EXPECT_EQ(runtime->last_ik_report().outcome, protocol::IkOutcome::rejected_malformed);
    EXPECT_EQ(runtime->last_event(), FaultCode::target_malformed);
  }

  FrameInputs inputs;
};

TEST_F(FrameInputsTest, FramesThatAreNoInputAreLeftToOthers) {
  hal::CanFrame status;
  status.id = protocol::kStatusFrames.id;
  EXPECT_FALSE(inputs.take(status, *runtime));
  EXPECT_FALSE(inputs.take(frame_of(protocol::UpdateData{}), *runtime));
  EXPECT_EQ(rejected(), 0u);
}

TEST_F(FrameInputsTest, CableFeedbackOfASegmentTheModelLacksIsRejected) {
  protocol::CableFeedback feedback{1, {120.0, 120.5, 121.0, 119.5}};
  EXPECT_TRUE(inputs.take(frame_of(feedback), *runtime));
  EXPECT_EQ(rejected(), 0u);
  feedback.segment = 2;  // the model has two
  EXPECT_TRUE(inputs.take(frame_of(feedback), *runtime));
  EXPECT_EQ(rejected(), 1u);
  EXPECT_EQ(runtime->last_event(), FaultCode::cable_frame_malformed);
  EXPECT_TRUE(inputs.take(truncated(frame_of(protocol::CableFeedback{0, {120, 120, 120, 120}})), *runtime));
  EXPECT_EQ(rejected(), 2u);
}

TEST_F(FrameInputsTest, APositionTargetNeedsItsXyPart) {
  EXPECT_TRUE(inputs.take(commit(7), *runtime));
  EXPECT_EQ(targets(), 1u);
  expect_refused(7);

  EXPECT_TRUE(inputs.take(position_xy(10.0, -5.0), *runtime));
  EXPECT_TRUE(inputs.take(commit(8), *runtime));
  EXPECT_EQ(targets(), 2u);
  EXPECT_EQ(rejected(), 1u);
  EXPECT_TRUE(runtime->ik_running());
}

// The runtime's set_target drops the parts of its own FrameInputs (which
// is how a commit takes them); this one's are dropped by hand.
TEST_F(FrameInputsTest, DroppedPartsAreNotSolved) {
  inputs.take(position_xy(10.0, -5.0), *runtime);
  inputs.drop_parts();
  inputs.take(commit(3), *runtime);
  expect_refused(3);
}

TEST_F(FrameInputsTest, APoseTargetNeedsItsOrientationToo) {
  inputs.take(position_xy(10.0, -5.0), *runtime);
  inputs.take(commit(4, protocol::TargetMode::pose), *runtime);
  expect_refused(4);
  inputs.take(position_xy(10.0, -5.0), *runtime);
  inputs.take(frame_of(protocol::TargetOrientation{1, 0, 0, 0}), *runtime);
  inputs.take(commit(5, protocol::TargetMode::pose), *runtime);
  EXPECT_EQ(rejected(), 1u);
  EXPECT_TRUE(runtime->ik_running());
}

TEST_F(FrameInputsTest, AMalformedPartDropsTheOneBeforeIt) {
  inputs.take(position_xy(10.0, -5.0), *runtime);
  EXPECT_TRUE(inputs.take(truncated(position_xy(10.0, -5.0)), *runtime));
  EXPECT_EQ(runtime->last_event(), FaultCode::target_malformed);
  inputs.take(commit(6), *runtime);
  expect_refused(6);
  EXPECT_EQ(rejected(), 2u);

  inputs.take(position_xy(10.0, -5.0), *runtime);
  inputs.take(frame_of(protocol::TargetOrientation{1, 0, 0, 0}), *runtime);
  inputs.take(truncated(frame_of(protocol::TargetOrientation{1, 0, 0, 0})), *runtime);
  inputs.take(commit(9, protocol::TargetMode::pose), *runtime);
  expect_refused(9);
}

TEST_F(FrameInputsTest, AMalformedCommitIsAnsweredWithItsSequence) {
  inputs.take(position_xy(10.0, -5.0), *runtime);
  hal::CanFrame bad_commit = commit(0x2A);
  bad_commit.dlc = 8;  // two bytes too many; the sequence is where it was
  EXPECT_TRUE(inputs.take(bad_commit, *runtime));
  expect_refused(0x2A);
}

TEST_F(FrameInputsTest, PayloadAndHoming) {
  EXPECT_TRUE(inputs.take(frame_of(protocol::Payload{0.5}), *runtime));
  EXPECT_TRUE(runtime->payload_received());
  EXPECT_EQ(runtime->payload_kg(), 0.5f);
  EXPECT_TRUE(inputs.take(truncated(frame_of(protocol::Payload{0.25})), *runtime));
  EXPECT_EQ(runtime->last_event(), FaultCode::payload_invalid);
  EXPECT_EQ(runtime->payload_kg(), 0.5f);

  EXPECT_TRUE(inputs.take(frame_of(protocol::Homing{}), *runtime));
  EXPECT_EQ(rejected(), 1u);
  EXPECT_TRUE(inputs.take(truncated(frame_of(protocol::Homing{})), *runtime));
  EXPECT_EQ(runtime->last_event(), FaultCode::homing_malformed);
  EXPECT_EQ(rejected(), 2u);

  // Without drives behind a backend a recover command changes nothing.
  EXPECT_TRUE(inputs.take(frame_of(protocol::DrivesCommand{}), *runtime));
  EXPECT_EQ(rejected(), 2u);
  EXPECT_TRUE(inputs.take(truncated(frame_of(protocol::DrivesCommand{})), *runtime));
  EXPECT_EQ(runtime->last_event(), FaultCode::drives_command_malformed);
  EXPECT_EQ(rejected(), 3u);
}

}  // namespace
}  // namespace cdcr::firmware
