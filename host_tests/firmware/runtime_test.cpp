// The runtime's state machine and per-cycle behaviour on the simulated
// platform: boot on good and bad images, input validation, stale input
// (per segment: a pose needs every segment's cables, so one drive falling
// silent while the others keep reporting must fault the runtime as surely as
// a silent bus, and its return must recover), inverse kinematics requests.

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "runtime_test_fixture.hpp"

namespace cdcr::firmware {
namespace {

namespace protocol = firmware::protocol;
using test_support::RuntimeTest;

TEST_F(RuntimeTest, ValidImageBootsIntoRunAndPublishesCompensatedPoses) {
  boot(test_support::small_image());
  EXPECT_EQ(runtime->state(), RuntimeState::run);
  EXPECT_EQ(runtime->active_fault(), FaultCode::none);
  cycles(20);
  EXPECT_EQ(runtime->state(), RuntimeState::run);
  ASSERT_TRUE(runtime->has_pose());
  EXPECT_TRUE(runtime->latest_pose().compensated);
  EXPECT_EQ(runtime->statistics().poses_published, 20u);
  EXPECT_EQ(runtime->statistics().rejected_frames, 0u);
  EXPECT_EQ(runtime->statistics().cycles, 20u);
  EXPECT_EQ(runtime->statistics().overruns, 0u);

  bool saw_status = false;
  for (const hal::CanFrame& frame : host_frames()) {
    protocol::Status status;
    if (protocol::decode(frame, status) != protocol::DecodeStatus::ok) continue;
    saw_status = true;
    EXPECT_EQ(status.state, RuntimeState::run);
    EXPECT_EQ(status.fault, FaultCode::none);
  }
  EXPECT_TRUE(saw_status);
}

TEST_F(RuntimeTest, CorruptedImageDegradesToNominalKinematics) {
  std::vector<std::uint8_t> image = test_support::small_image();
  image[image.size() / 2] ^= 0x40;
  boot(image);
  EXPECT_EQ(runtime->state(), RuntimeState::degraded);
  EXPECT_EQ(runtime->boot_fault(), FaultCode::image_invalid);
  EXPECT_EQ(runtime->boot_fault_detail(), FaultDetail(model::ImageStatus::checksum_mismatch));
  EXPECT_EQ(runtime->active_fault(), FaultCode::image_invalid);
  cycles(20);
  EXPECT_EQ(runtime->state(), RuntimeState::degraded);
  ASSERT_TRUE(runtime->has_pose());
  EXPECT_FALSE(runtime->latest_pose().compensated);

  // On the bus: STATS carries the parser's verdict, typed by STATUS's FAULT.
  const std::vector<hal::CanFrame> frames = host_frames();
  protocol::Status status;
  ASSERT_TRUE(last_of(frames, status));
  EXPECT_EQ(status.state, RuntimeState::degraded);
  EXPECT_EQ(status.fault, FaultCode::image_invalid);
  protocol::Stats stats;
  bool saw_stats = false;
  for (const hal::CanFrame& frame : frames) {
    saw_stats = protocol::decode(frame, status.fault, stats) == protocol::DecodeStatus::ok || saw_stats;
  }
  ASSERT_TRUE(saw_stats);
  EXPECT_EQ(stats.fault_detail.kind(), FaultDetailKind::image_status);
  EXPECT_EQ(stats.fault_detail.image_status(), model::ImageStatus::checksum_mismatch);
}

// Without a valid image the same solver solves the nominal model: the
// setpoints put the nominal tip (computed here from their joints) on the target.
TEST_F(RuntimeTest, DegradedRuntimeSolvesTargetsOnTheNominalModel) {
  std::vector<std::uint8_t> image = test_support::small_image();
  image[image.size() / 2] ^= 0x40;
  boot(image);
  cycles(3);
  ASSERT_EQ(runtime->state(), RuntimeState::degraded);
  const model::Vec3<Scalar> target = runtime->latest_pose().pose.position_mm + model::Vec3<Scalar>(4, -3, 0);
  host_frames();
  send_position_target(target.x(), target.y(), target.z(), 9);
  cycles_until_ik_done();
  protocol::IkReport report;
  ASSERT_TRUE(last_ik_report(report));
  EXPECT_EQ(report.sequence, 9);
  EXPECT_EQ(report.outcome, protocol::IkOutcome::converged);
  ASSERT_TRUE(runtime->has_setpoints());
  const model::Pose<Scalar> nominal =
      model::forward_kinematics_bend(model::bend_from_joints(runtime->setpoint_joints()), runtime->geometry());
  EXPECT_LT((nominal.position_mm - target).norm(), kIkAcceptedPositionErrorMm);
}

TEST_F(RuntimeTest, TruncatedImageDegrades) {
  std::vector<std::uint8_t> image = test_support::small_image();
  image.resize(image.size() - 9);
  boot(image);
  EXPECT_EQ(runtime->state(), RuntimeState::degraded);
  EXPECT_EQ(runtime->boot_fault(), FaultCode::image_invalid);
  EXPECT_EQ(runtime->boot_fault_detail(), FaultDetail(model::ImageStatus::truncated));
  cycles(5);
  EXPECT_TRUE(runtime->has_pose());
}

TEST_F(RuntimeTest, MissingImageDegrades) {
  boot({});
  EXPECT_EQ(runtime->state(), RuntimeState::degraded);
  EXPECT_EQ(runtime->boot_fault(), FaultCode::image_missing);
  EXPECT_EQ(runtime->geometry().segment_count, 2);
}

TEST_F(RuntimeTest, MalformedCableFramesAreCountedAndRejected) {
  boot(test_support::small_image());
  cycles(3);
  const PoseEstimate before = runtime->latest_pose();
  drives->set_silent(true);

  hal::CanFrame short_frame;
  ASSERT_TRUE(protocol::encode(protocol::CableFeedback{0, {120, 120, 120, 120}}, short_frame));
  short_frame.dlc = 6;
  send(short_frame);
  hal::CanFrame unavailable;
  ASSERT_TRUE(protocol::encode(protocol::CableFeedback{0, {120, 120, 120, 120}}, unavailable));
  protocol::write_raw(unavailable, protocol::cable_lengths::kL2, protocol::kCableNotAvailableRaw);
  send(unavailable);
  hal::CanFrame unknown_segment;  // the image has 2 segments
  ASSERT_TRUE(protocol::encode(protocol::CableFeedback{5, {120, 120, 120, 120}}, unknown_segment));
  send(unknown_segment);
  cycles(1);

  EXPECT_EQ(runtime->statistics().rejected_frames, 3u);
  EXPECT_EQ(runtime->last_event(), FaultCode::cable_frame_malformed);
  EXPECT_EQ(runtime->active_fault(), FaultCode::cable_frame_malformed);
  EXPECT_EQ(runtime->latest_pose().pose.position_mm, before.pose.position_mm);
  EXPECT_EQ(runtime->state(), RuntimeState::run);
}

TEST_F(RuntimeTest, ImpossibleCableLengthsAreRejected) {
  boot(test_support::small_image());
  cycles(3);
  drives->set_silent(true);
  const std::uint32_t published = runtime->statistics().poses_published;
  // A difference of 390 mm across a 67 mm anchor radius is a bend of 2.9 rad.
  hal::CanFrame frame;
  ASSERT_TRUE(protocol::encode(protocol::CableFeedback{0, {10.0, 120.0, 400.0, 120.0}}, frame));
  send(frame);
  ASSERT_TRUE(protocol::encode(protocol::CableFeedback{1, {120.0, 120.0, 120.0, 120.0}}, frame));
  send(frame);
  cycles(1);
  EXPECT_EQ(runtime->statistics().rejected_cable_sets, 1u);
  EXPECT_EQ(runtime->last_event(), FaultCode::cable_lengths_invalid);
  EXPECT_EQ(runtime->active_fault_detail(), FaultDetail(model::Status::cable_difference_out_of_range));
  EXPECT_EQ(runtime->statistics().poses_published, published);
}

TEST_F(RuntimeTest, NonFiniteCableLengthsAreRejectedByTheForwardPath) {
  boot(test_support::small_image());
  Cables cables = test_support::bent_cables(runtime->geometry()).cast<Scalar>();
  PoseEstimate estimate;
  ASSERT_EQ(runtime->estimate_pose(cables, estimate), model::Status::ok);
  cables[2] = std::nanf("");
  EXPECT_EQ(runtime->estimate_pose(cables, estimate), model::Status::non_finite_input);
  cables[2] = -5.0f;
  EXPECT_NE(runtime->estimate_pose(cables, estimate), model::Status::ok);
}

TEST_F(RuntimeTest, StaleInputFaultsAndRecovers) {
  boot(test_support::small_image());
  cycles(5);
  drives->set_silent(true);
  cycles(kStaleInputCycles);
  EXPECT_EQ(runtime->state(), RuntimeState::run);
  cycles(1);
  EXPECT_EQ(runtime->state(), RuntimeState::fault);
  EXPECT_EQ(runtime->active_fault(), FaultCode::cable_input_stale);
  EXPECT_EQ(runtime->statistics().stale_events, 1u);
  const std::uint32_t published = runtime->statistics().poses_published;

  host_frames();
  send_position_target(10, 10, 200, 9);
  cycles(1);
  EXPECT_EQ(runtime->last_ik_report().outcome, protocol::IkOutcome::rejected_state);
  EXPECT_FALSE(runtime->has_setpoints());
  cycles(20);
  EXPECT_EQ(runtime->statistics().poses_published, published);
  EXPECT_EQ(runtime->statistics().stale_events, 1u);

  drives->set_silent(false);
  cycles(1);
  EXPECT_EQ(runtime->state(), RuntimeState::run);
  EXPECT_EQ(runtime->active_fault(), FaultCode::none);
  EXPECT_EQ(runtime->statistics().poses_published, published + 1);
}

TEST_F(RuntimeTest, ReachableTargetPublishesSetpointsAndTheDrivesFollow) {
  boot(test_support::small_image());
  cycles(3);
  const model::Vec3<Scalar> target = runtime->latest_pose().pose.position_mm + model::Vec3<Scalar>(3, -2, 0);
  // Whatever sits in the host queue from boot is not the answer.
  host_frames();
  send_position_target(target.x(), target.y(), target.z(), 42);
  const int spent = cycles_until_ik_done();
  protocol::IkReport report;
  ASSERT_TRUE(last_ik_report(report));
  EXPECT_EQ(report.sequence, 42);
  EXPECT_EQ(report.outcome, protocol::IkOutcome::converged);
  EXPECT_EQ(report.cycles, spent);
  EXPECT_GE(report.iterations, 1);
  EXPECT_LE(report.position_residual_mm, double(kIkAcceptedPositionErrorMm));
  EXPECT_EQ(report.orientation_residual_rad, 0.0);  // a position target
  ASSERT_TRUE(runtime->has_setpoints());
  cycles(500);
  EXPECT_LT((runtime->latest_pose().pose.position_mm - target).norm(), 0.05f);
}

TEST_F(RuntimeTest, UnreachableTargetIsReportedAndSetpointsHeld) {
  boot(test_support::small_image());
  cycles(3);
  const model::Vec3<Scalar> reachable = runtime->latest_pose().pose.position_mm + model::Vec3<Scalar>(1, 1, 0);
  send_position_target(reachable.x(), reachable.y(), reachable.z(), 1);
  cycles_until_ik_done();
  ASSERT_TRUE(runtime->has_setpoints());
  const Cables held = runtime->setpoints_mm();
  cycles(5);
  const std::uint32_t setpoint_frames = drives->setpoint_frames();

  host_frames();
  send_position_target(900.0, 0.0, 50.0, 2);
  cycles_until_ik_done();
  EXPECT_EQ(runtime->setpoints_mm(), held);
  EXPECT_EQ(runtime->last_ik_report().model_status, model::Status::ik_not_converged);
  EXPECT_EQ(runtime->last_event(), FaultCode::target_unreachable);
  protocol::IkReport report;
  ASSERT_TRUE(last_of(host_frames(), report));
  cycles(kStatusEveryCycles);
  EXPECT_EQ(drives->setpoint_frames(), setpoint_frames);
  EXPECT_EQ(runtime->state(), RuntimeState::run);

  const std::vector<hal::CanFrame> frames = host_frames();
  EXPECT_EQ(report.sequence, 2);
  EXPECT_EQ(report.outcome, protocol::IkOutcome::unreachable);
  EXPECT_GT(report.position_residual_mm, 1.0);
  // The next STATUS names the event, and STATS the solver's status with it.
  bool reported = false;
  protocol::Status status;
  for (const hal::CanFrame& frame : frames) {
    protocol::Stats stats;
    if (protocol::decode(frame, status) == protocol::DecodeStatus::ok) continue;
    if (protocol::decode(frame, status.fault, stats) != protocol::DecodeStatus::ok) continue;
    EXPECT_EQ(status.fault, FaultCode::target_unreachable);
    EXPECT_EQ(stats.fault_detail, FaultDetail(model::Status::ik_not_converged));
    reported = true;
    break;
  }
  EXPECT_TRUE(reported);
}

TEST_F(RuntimeTest, TargetWithoutItsPositionFrameIsMalformed) {
  boot(test_support::small_image());
  cycles(3);
  send_frame(protocol::TargetPositionZ{150.0, protocol::TargetMode::position, false, 7});
  cycles(1);
  EXPECT_EQ(runtime->last_ik_report().outcome, protocol::IkOutcome::rejected_malformed);
  EXPECT_EQ(runtime->last_ik_report().sequence, 7);
  EXPECT_EQ(runtime->last_event(), FaultCode::target_malformed);
  EXPECT_FALSE(runtime->has_setpoints());
}

// The one quaternion rule (model/unit_quaternion.hpp): a norm within 1e-3
// of 1 is rounding and is normalised; one further off is a mistake.
TEST_F(RuntimeTest, PoseTargetQuaternionMustBeUnitWithinTheSharedTolerance) {
  boot(test_support::small_image());
  cycles(3);
  const model::Vec3<Scalar> here = runtime->latest_pose().pose.position_mm;
  const auto outcome_for_norm = [&](double norm, std::uint8_t sequence) {
    const double c = 0.5 * norm;  // (0.5, 0.5, 0.5, 0.5) has unit norm
    send_frame(protocol::TargetOrientation{c, c, c, c});
    send_frame(protocol::TargetPositionXy{here.x(), here.y()});
    send_frame(protocol::TargetPositionZ{here.z(), protocol::TargetMode::pose, false, sequence});
    cycles_until_ik_done();
    EXPECT_EQ(runtime->last_ik_report().sequence, sequence);
    return runtime->last_ik_report().outcome;
  };
  EXPECT_NE(outcome_for_norm(1.0 + 0.6e-3, 31), protocol::IkOutcome::rejected_malformed);
  EXPECT_NE(outcome_for_norm(1.0 - 0.6e-3, 32), protocol::IkOutcome::rejected_malformed);
  EXPECT_EQ(outcome_for_norm(1.0 + 2e-3, 33), protocol::IkOutcome::rejected_malformed);
  EXPECT_EQ(runtime->last_event(), FaultCode::target_malformed);
  EXPECT_EQ(outcome_for_norm(1.0 - 2e-3, 34), protocol::IkOutcome::rejected_malformed);
}

TEST_F(RuntimeTest, TargetWithReservedBitsSetIsMalformed) {
  boot(test_support::small_image());
  cycles(3);
  const model::Vec3<Scalar> reachable = runtime->latest_pose().pose.position_mm + model::Vec3<Scalar>(1, 1, 0);
  send_frame(protocol::TargetPositionXy{reachable.x(), reachable.y()});
  hal::CanFrame commit;
  protocol::encode(protocol::TargetPositionZ{reachable.z(), protocol::TargetMode::position, false, 11}, commit);
  // Bits 34..39 of TARGET_POSITION_Z are reserved: a sender that sets one
  // means something this runtime does not know.
  constexpr protocol::SignalSpec kReservedBit39{"RESERVED", 39, 1, false, 1, 0, 0, 1, ""};
  protocol::write_raw(commit, kReservedBit39, 1);
  send(commit);
  cycles(1);
  protocol::IkReport report;
  ASSERT_TRUE(last_ik_report(report));
  EXPECT_EQ(report.sequence, 11);
  EXPECT_EQ(report.outcome, protocol::IkOutcome::rejected_malformed);
  EXPECT_EQ(runtime->last_event(), FaultCode::target_malformed);
  EXPECT_FALSE(runtime->has_setpoints());
}

TEST_F(RuntimeTest, TrackingTargetsAreSolvedLikeSingleOnes) {
  boot(test_support::small_image());
  cycles(3);
  const model::Vec3<Scalar> start = runtime->latest_pose().pose.position_mm;
  for (int k = 1; k <= 5; ++k) {
    const model::Vec3<Scalar> target = start + model::Vec3<Scalar>(0.2f * k, -0.1f * k, 0);
    send_frame(protocol::TargetPositionXy{target.x(), target.y()});
    send_frame(protocol::TargetPositionZ{target.z(), protocol::TargetMode::position, true, std::uint8_t(k)});
    cycles_until_ik_done();
    protocol::IkReport report;
    ASSERT_TRUE(last_ik_report(report));
    EXPECT_EQ(report.sequence, k);
    EXPECT_EQ(report.outcome, protocol::IkOutcome::converged);
  }
}

TEST_F(RuntimeTest, OneSilentSegmentFaultsAndItsReturnRecovers) {
  boot(test_support::small_image());
  ASSERT_EQ(runtime->geometry().segment_count, 2);
  cycles(5);
  ASSERT_EQ(runtime->state(), RuntimeState::run);

  drives->set_segment_silent(1, true);
  int cycles_to_fault = 0;
  while (runtime->state() != RuntimeState::fault && cycles_to_fault < 5 * kStaleInputCycles) {
    const std::uint32_t poses_before = runtime->statistics().poses_published;
    cycles(1);
    ++cycles_to_fault;
    // Until the fault, every cycle publishes a pose: no cycle in RUN is
    // silent while the segment's last frames are still within the limit.
    if (runtime->state() == RuntimeState::run) {
      EXPECT_EQ(runtime->statistics().poses_published, poses_before + 1) << "cycle " << cycles_to_fault;
    }
  }
  ASSERT_EQ(runtime->state(), RuntimeState::fault);
  // The segment's frames may be up to kStaleInputCycles old; one more and
  // the input is stale, however fresh the other segment's frames are.
  EXPECT_EQ(cycles_to_fault, kStaleInputCycles + 1);
  EXPECT_EQ(runtime->active_fault(), FaultCode::cable_input_stale);
  EXPECT_EQ(runtime->statistics().stale_events, 1u);

  host_frames();
  const std::uint32_t published = runtime->statistics().poses_published;
  for (int i = 0; i < 3 * kStatusEveryCycles; ++i) {
    cycles(1);
    ASSERT_EQ(runtime->state(), RuntimeState::fault) << "cycle " << i << " after the fault";
  }
  EXPECT_EQ(runtime->statistics().poses_published, published);
  EXPECT_EQ(runtime->statistics().stale_events, 1u);
  protocol::Status status;
  ASSERT_TRUE(last_of(host_frames(), status));
  EXPECT_EQ(status.state, RuntimeState::fault);
  EXPECT_EQ(status.fault, FaultCode::cable_input_stale);

  drives->set_segment_silent(1, false);
  cycles(1);
  EXPECT_EQ(runtime->state(), RuntimeState::run);
  EXPECT_EQ(runtime->active_fault(), FaultCode::none);
  EXPECT_EQ(runtime->statistics().poses_published, published + 1);
  cycles(20);
  EXPECT_EQ(runtime->state(), RuntimeState::run);
  EXPECT_EQ(runtime->statistics().poses_published, published + 21);
}

}  // namespace
}  // namespace cdcr::firmware
