// The runtime's predictive variance: spread over a few cycles within the
// cycle's work budget, sent as POSE_UNCERTAINTY for the pose it belongs to,
// equal to what the same code gives in one go, and the extrapolation flag
// in the pose frame and STATUS.

#include <algorithm>
#include <cstring>
#include <map>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "cdcr/firmware/ik_settings.hpp"
#include "cdcr/model/crc32.hpp"
#include "runtime_test_fixture.hpp"
#include "train/predictive_variance.hpp"
#include "../support/variance_block.hpp"

namespace cdcr::firmware {
namespace {

namespace protocol = firmware::protocol;
using test_support::RuntimeTest;

// The fixture's small model with one kernel for every output and a variance
// factor of `rank` points over its rows.
std::vector<std::uint8_t> image_with_variance(int rank, double extrapolation_variance = 1.0, int points = 200) {
  training::TrainedModel m = test_support::small_correction_model(points);
  test_support::add_variance_block(m, rank);
  m.variance.extrapolation_variance = extrapolation_variance;
  return exporting::write_image(m);
}

class RuntimeUncertaintyTest : public RuntimeTest {
 protected:
  void listen_to_poses() {
    const hal::CanFilter host_filters[] = {protocol::kPoseFrames, protocol::kStatusFrames};
    platform->host_node.set_filters(host_filters, 2);
  }

  // A position target with REFUSE_EXTRAPOLATING set or not.
  void send_guarded_position_target(const Eigen::Vector3d& position_mm, std::uint8_t sequence,
                                    bool refuse_extrapolating) {
    protocol::TargetPositionZ commit{position_mm.z(), protocol::TargetMode::position, false, sequence};
    commit.refuse_extrapolating = refuse_extrapolating;
    send_frame(protocol::TargetPositionXy{position_mm.x(), position_mm.y()});
    send_frame(commit);
  }
};

// A request prefers solutions in the middle of the bends the model was
// fitted on, each bend weighted by the inverse square of its range's
// half-width (the narrowest range weighing 1); the nominal model, which is as
// sure everywhere, has no preference.
TEST(IkPreference, IsTheMiddleOfTheFittedRange) {
  const std::vector<std::uint8_t> bytes = image_with_variance(16);
  model::ImageView image{};
  ASSERT_EQ(model::parse_image(bytes.data(), bytes.size(), image, model::ImageCapacity{}), model::ImageStatus::ok);
  ASSERT_EQ(image.encoding, model::InputEncoding::bend_vector);
  Geometry geometry;
  ASSERT_EQ(model::geometry_from_image(image, geometry), model::Status::ok);
  const model::IkPreference<Scalar, kMaxSegments> preference = ik_preference(geometry, &image);
  const int columns = 2 * geometry.segment_count;
  ASSERT_EQ(preference.centre.size(), columns);
  EXPECT_GT(preference.gain, 0.0f);
  double narrowest = 1e9;
  for (int d = 0; d < columns; ++d) {
    narrowest = std::min(narrowest, double(image.input_max[d]) - double(image.input_min[d]));
  }
  for (int d = 0; d < columns; ++d) {
    const double width = double(image.input_max[d]) - double(image.input_min[d]);
    EXPECT_NEAR(preference.centre[d], 0.5 * (image.input_max[d] + image.input_min[d]), 1e-6) << d;
    EXPECT_NEAR(preference.weight[d], (narrowest * narrowest) / (width * width), 1e-5) << d;
  }
  EXPECT_EQ(ik_preference(geometry, nullptr).gain, 0.0f);
}

TEST_F(RuntimeUncertaintyTest, RadiiOfARecentPoseGoOutEveryFewCycles) {
  boot(image_with_variance(64));
  ASSERT_EQ(runtime->state(), RuntimeState::run);
  listen_to_poses();
  // The variance's slice comes out of IK's share of the cycle.
  EXPECT_EQ(runtime->ik_units_per_cycle(),
            kCycleWorkUnits - kWorkCosts.cycle_overhead - 200 - kUncertaintyUnitsPerCycle);

  std::map<std::uint8_t, model::Pose<float>> poses;  // by sequence, within the window
  std::vector<protocol::PoseUncertainty> radii;
  PoseEstimate latest;
  for (int cycle = 0; cycle < 40; ++cycle) {
    cycles(1);
    latest = runtime->latest_pose();
    for (const hal::CanFrame& frame : host_frames()) {
      protocol::PosePositionZ z;
      if (protocol::decode(frame, z) == protocol::DecodeStatus::ok) {
        EXPECT_FALSE(z.extrapolating);
        poses[z.sequence] = latest.pose;
      }
      protocol::PoseUncertainty u;
      if (protocol::decode(frame, u) == protocol::DecodeStatus::ok) radii.push_back(u);
    }
  }
  EXPECT_EQ(runtime->statistics().overruns, 0u);
  // 832 units at 192 a cycle: five slices, and the next evaluation starts
  // with the next cycle's pose.
  EXPECT_GE(radii.size(), 6u);
  EXPECT_LE(radii.size(), 8u);
  // Each for a pose that went out, and what the same code gives in one go
  // for that pose (the drives hold still, so every pose is the latest one).
  const model::PoseUncertainty<Scalar> whole = runtime->estimate_uncertainty(latest);
  ASSERT_GT(whole.r95_mm, 0.0f);
  for (const protocol::PoseUncertainty& u : radii) {
    EXPECT_EQ(poses.count(u.sequence), 1u) << int(u.sequence);
    EXPECT_NEAR(u.r95_position_mm, whole.r95_mm, 0.0006);
    EXPECT_NEAR(u.r95_orientation_deg, whole.r95_deg, 0.0006);
    EXPECT_NEAR(u.latent_share, whole.latent_share, 0.003);
    EXPECT_FALSE(u.extrapolating);
  }
  EXPECT_TRUE(runtime->has_uncertainty());
}

// While IK runs, the variance gets a slice every few cycles only, and IK
// the rest of those cycles' budget; radii keep coming, more slowly.
TEST_F(RuntimeUncertaintyTest, IkKeepsItsShareWhileTheVarianceWaits) {
  boot(image_with_variance(64));
  listen_to_poses();
  cycles(5);
  host_frames();
  const std::uint32_t beside_variance = runtime->ik_units_per_cycle();
  const model::Pose<double> target = runtime->latest_pose().pose.cast<double>();
  send_position_target(target.position_mm.x() + 2.0, target.position_mm.y(), target.position_mm.z(), 3);
  int radii = 0;
  int cycles_with_full_share = 0;
  int solving_cycles = 0;
  for (int cycle = 0; cycle < 200; ++cycle) {
    cycles(1);
    if (runtime->ik_running()) {
      ++solving_cycles;
      if (runtime->ik_units_per_cycle() == beside_variance + kUncertaintyUnitsPerCycle) ++cycles_with_full_share;
    }
    for (const hal::CanFrame& frame : host_frames()) {
      protocol::PoseUncertainty u;
      if (protocol::decode(frame, u) == protocol::DecodeStatus::ok) ++radii;
    }
  }
  EXPECT_GT(solving_cycles, 0);
  EXPECT_GE(cycles_with_full_share, solving_cycles * 3 / 4) << solving_cycles;
  EXPECT_GT(radii, 5);
  EXPECT_EQ(runtime->statistics().overruns, 0u);
}

// At the runtime's capacity, on a board whose budget does not hold the
// forward path, a slice and IK's smallest step together (the Cortex-M7's),
// the variance waits while IK runs; where it does (the host's), it gets its
// slice every few cycles as with any model.
TEST_F(RuntimeUncertaintyTest, AtTheCapacityTheVarianceNeverPushesACycleOverBudget) {
  constexpr std::uint32_t forward = kWorkCosts.cycle_overhead + kMaxTrainingPoints;
  constexpr bool fits = forward + kUncertaintyUnitsPerCycle + kMinIkUnitsPerCycle <= kCycleWorkUnits;
  boot(image_with_variance(16, 1.0, static_cast<int>(kMaxTrainingPoints)));
  ASSERT_EQ(runtime->state(), RuntimeState::run);
  listen_to_poses();
  cycles(3);
  const model::Pose<double> target = runtime->latest_pose().pose.cast<double>();
  send_position_target(target.position_mm.x() + 2.0, target.position_mm.y(), target.position_mm.z(), 4);
  const std::uint32_t alone = std::max(kCycleWorkUnits - forward, kMinIkUnitsPerCycle);
  int solving_cycles = 0;
  int beside_variance = 0;
  for (int cycle = 0; cycle < 60 && (cycle < 2 || runtime->ik_running()); ++cycle) {
    cycles(1);
    if (!runtime->ik_running()) continue;
    ++solving_cycles;
    if (runtime->ik_units_per_cycle() != alone) {
      ++beside_variance;
      // Never below IK's smallest step, never past the budget.
      EXPECT_GE(runtime->ik_units_per_cycle(), kMinIkUnitsPerCycle);
      EXPECT_LE(forward + kUncertaintyUnitsPerCycle + runtime->ik_units_per_cycle(), kCycleWorkUnits);
    }
  }
  EXPECT_GT(solving_cycles, 8);
  if (fits) {
    EXPECT_GT(beside_variance, 0);
  } else {
    EXPECT_EQ(beside_variance, 0);
  }
}

TEST_F(RuntimeUncertaintyTest, APoseBeyondTheFittedRangeIsFlaggedInThePoseAndStatus) {
  // A threshold of a thousandth of the prior: the held pose's variance,
  // above it, makes it extrapolate.
  boot(image_with_variance(16, 1e-3));
  listen_to_poses();
  cycles(30);
  ASSERT_TRUE(runtime->has_uncertainty());
  ASSERT_GT(runtime->latest_uncertainty().latent_share, 1e-3f);
  EXPECT_TRUE(runtime->extrapolating());
  bool pose_flag = false;
  bool status_flag = false;
  for (const hal::CanFrame& frame : host_frames()) {
    protocol::PosePositionZ z;
    if (protocol::decode(frame, z) == protocol::DecodeStatus::ok) pose_flag = pose_flag || z.extrapolating;
    protocol::Status status;
    if (protocol::decode(frame, status) == protocol::DecodeStatus::ok) status_flag = status_flag || status.extrapolating;
  }
  EXPECT_TRUE(pose_flag);
  EXPECT_TRUE(status_flag);
}

// The outcomes the host heard, in order.
std::vector<protocol::IkOutcome> outcomes_in(const std::vector<hal::CanFrame>& frames, int* setpoint_frames) {
  std::vector<protocol::IkOutcome> outcomes;
  for (const hal::CanFrame& frame : frames) {
    protocol::IkReport report;
    if (protocol::decode(frame, report) == protocol::DecodeStatus::ok) outcomes.push_back(report.outcome);
    protocol::CableSetpoint setpoint;
    if (protocol::decode(frame, setpoint) == protocol::DecodeStatus::ok) ++*setpoint_frames;
  }
  return outcomes;
}

// The fitted range a narrow box around the held pose's inputs: a target
// whose solution bends further is outside it. Without a variance block the
// range alone decides; with one in an image before 2.6, the range decides
// before the variance runs; from 2.6 the variance alone decides, and the
// range does not refuse. Parameters: the variance rank, the image's minor
// version.
class RefusalOutsideTheRange : public RuntimeUncertaintyTest,
                               public ::testing::WithParamInterface<std::tuple<int, int>> {};

// The image with its minor version set and its CRC made good again.
std::vector<std::uint8_t> with_minor_version(std::vector<std::uint8_t> image, std::uint16_t minor) {
  std::memcpy(image.data() + 6, &minor, sizeof minor);
  const std::uint32_t crc = model::crc32(image.data(), image.size() - model::kImageTrailerSize);
  std::memcpy(image.data() + image.size() - model::kImageTrailerSize, &crc, sizeof crc);
  return image;
}

TEST_P(RefusalOutsideTheRange, ATargetThatRefusesExtrapolationIsRefusedOutsideTheFittedRange) {
  const auto [rank, minor] = GetParam();
  const bool range_flags = rank == 0 || minor < model::kImageVersionMinorHeldOutThreshold;
  training::TrainedModel m = test_support::small_correction_model(200);
  test_support::add_variance_block(m, rank);
  if (rank > 0) m.variance.extrapolation_variance = 1.0;  // the variance alone never flags
  {
    // The held pose (fixture's bent cables) before the image is made: boot
    // once without a model to read its joints.
    boot(test_support::small_image());
    cycles(3);
    const Joints bend = model::bend_from_joints(runtime->latest_pose().joints);
    m.input_min = bend.cast<double>().array() - 0.02;
    m.input_max = bend.cast<double>().array() + 0.02;
  }
  const std::vector<std::uint8_t> image =
      with_minor_version(exporting::write_image(m), static_cast<std::uint16_t>(minor));
  for (const bool refuse : {true, false}) {
    SCOPED_TRACE(refuse ? "refusing" : "accepting");
    boot(image);
    ASSERT_EQ(runtime->state(), RuntimeState::run);
    cycles(3);
    EXPECT_FALSE(runtime->latest_pose().outside_range);
    host_frames();
    // Where the tip is with the first segment bent 0.1 rad further (the
    // correction moves it a fraction of a millimetre): reachable, outside the box.
    Joints bend = model::bend_from_joints(runtime->latest_pose().joints);
    bend.head<2>() *= 1.0f + 0.1f / bend.head<2>().norm();
    const Eigen::Vector3d target = model::forward_kinematics_bend(bend, runtime->geometry()).position_mm.cast<double>();
    send_guarded_position_target(target, 9, refuse);
    const int cycles_spent_solving = cycles_until_ik_done();
    int setpoint_frames = 0;
    const std::vector<protocol::IkOutcome> outcomes = outcomes_in(host_frames(), &setpoint_frames);
    ASSERT_FALSE(outcomes.empty());
    if (refuse && range_flags) {
      EXPECT_EQ(outcomes.back(), protocol::IkOutcome::refused_extrapolating);
      // Refused when found, without the variance's cycles.
      EXPECT_EQ(runtime->last_ik_report().cycles, cycles_spent_solving);
      EXPECT_EQ(setpoint_frames, 0);
      EXPECT_FALSE(runtime->has_setpoints());
      // Its residual is the solution's: it was found, then refused.
      EXPECT_LT(runtime->last_ik_report().position_error_mm, kIkAcceptedPositionErrorMm);
    } else {
      EXPECT_EQ(outcomes.back(), protocol::IkOutcome::converged);
      EXPECT_EQ(setpoint_frames, runtime->geometry().segment_count);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(VarianceRanks, RefusalOutsideTheRange,
                         ::testing::Values(std::make_tuple(0, int(model::kImageVersionMinor)),
                                           std::make_tuple(16, int(model::kImageVersionMinorHeldOutThreshold - 1)),
                                           std::make_tuple(16, int(model::kImageVersionMinorHeldOutThreshold))));

// Within the fitted range, the variance decides, over a few cycles of IK's
// share: with a threshold above any share the solution goes out (later
// than without the check); with one below the held pose's share it is
// refused.
TEST_F(RuntimeUncertaintyTest, ATargetThatRefusesExtrapolationWaitsForTheVarianceOfItsSolution) {
  struct Case {
    double threshold;
    bool refuse;
    protocol::IkOutcome expected;
  };
  int cycles_spent[3] = {};
  const Case cases[] = {{1.0, false, protocol::IkOutcome::converged},
                        {1.0, true, protocol::IkOutcome::converged},
                        {1e-3, true, protocol::IkOutcome::refused_extrapolating}};
  for (int c = 0; c < 3; ++c) {
    SCOPED_TRACE(c);
    boot(image_with_variance(64, cases[c].threshold));
    ASSERT_EQ(runtime->state(), RuntimeState::run);
    cycles(3);
    host_frames();
    const Eigen::Vector3d target = runtime->latest_pose().pose.position_mm.cast<double>() + Eigen::Vector3d(2, 0, 0);
    send_guarded_position_target(target, 5, cases[c].refuse);
    cycles_spent[c] = cycles_until_ik_done();
    int setpoint_frames = 0;
    const std::vector<protocol::IkOutcome> outcomes = outcomes_in(host_frames(), &setpoint_frames);
    ASSERT_FALSE(outcomes.empty());
    EXPECT_EQ(outcomes.back(), cases[c].expected);
    EXPECT_EQ(setpoint_frames, cases[c].expected == protocol::IkOutcome::converged ? runtime->geometry().segment_count : 0);
    EXPECT_EQ(runtime->statistics().overruns, 0u);
  }
  // 832 units of variance in IK's share of a few hundred a cycle; a refused
  // solution is looked for once more, from the straight start.
  EXPECT_GE(cycles_spent[1], cycles_spent[0] + 1);
  EXPECT_GT(cycles_spent[2], cycles_spent[1]);
}

// A stream that refuses extrapolation gets no best point so far: every
// point is checked first. With a threshold below every share, nothing goes
// out; the same stream without the refusal moves the drives.
TEST_F(RuntimeUncertaintyTest, AStreamThatRefusesExtrapolationSendsOnlyCheckedPoints) {
  for (const bool refuse : {false, true}) {
    SCOPED_TRACE(refuse ? "refusing" : "accepting");
    boot(image_with_variance(64, 1e-3));
    cycles(3);
    host_frames();
    const Eigen::Vector3d start = runtime->latest_pose().pose.position_mm.cast<double>();
    int setpoint_frames = 0;
    std::vector<protocol::IkOutcome> outcomes;
    for (int k = 0; k < 60; ++k) {
      protocol::TargetPositionZ commit{start.z(), protocol::TargetMode::position, true, std::uint8_t(k)};
      commit.refuse_extrapolating = refuse;
      send_frame(protocol::TargetPositionXy{start.x() + 0.05 * k, start.y()});
      send_frame(commit);
      cycles(1);
      const std::vector<protocol::IkOutcome> heard = outcomes_in(host_frames(), &setpoint_frames);
      outcomes.insert(outcomes.end(), heard.begin(), heard.end());
    }
    if (refuse) {
      EXPECT_EQ(setpoint_frames, 0);
      EXPECT_EQ(std::count(outcomes.begin(), outcomes.end(), protocol::IkOutcome::converged), 0);
    } else {
      EXPECT_GT(setpoint_frames, 0);
    }
  }
}

TEST_F(RuntimeUncertaintyTest, WithoutAVarianceBlockNoRadiiGoOut) {
  boot(test_support::small_image());
  listen_to_poses();
  EXPECT_EQ(runtime->ik_units_per_cycle(), kCycleWorkUnits - kWorkCosts.cycle_overhead - 5);
  cycles(20);
  for (const hal::CanFrame& frame : host_frames()) {
    protocol::PoseUncertainty u;
    EXPECT_NE(protocol::decode(frame, u), protocol::DecodeStatus::ok);
  }
  EXPECT_FALSE(runtime->has_uncertainty());
}

// Publish rates (publish_rates.hpp): the pose every 4 cycles, a variance
// begun at most every 18 and only on a pose that went out (so every 20
// here: 18 cycles on is not a pose's cycle), STATUS and STATS every 25; the
// estimate still runs every cycle.
TEST_F(RuntimeUncertaintyTest, PublishRatesSpaceTheRuntimesOwnFrames) {
  boot(image_with_variance(64));
  ASSERT_EQ(runtime->state(), RuntimeState::run);
  PublishRates rates;
  rates.pose_every = 4;
  rates.uncertainty_every = 18;
  rates.status_every = 25;
  ASSERT_TRUE(runtime->set_publish_rates(rates));
  PublishRates invalid = rates;
  invalid.pose_every = 0;
  EXPECT_FALSE(runtime->set_publish_rates(invalid));
  invalid = rates;
  invalid.status_every = kMaxPublishEvery + 1;
  EXPECT_FALSE(runtime->set_publish_rates(invalid));
  EXPECT_EQ(runtime->publish_rates().pose_every, 4);
  listen_to_poses();

  int status_frames = 0;
  std::vector<int> pose_cycles;
  std::vector<std::uint8_t> pose_sequences;
  std::vector<int> radii_cycles;
  std::vector<std::uint8_t> radii_sequences;
  ASSERT_EQ(runtime->statistics().cycles, 0u);
  for (int cycle = 0; cycle < 100; ++cycle) {
    cycles(1);
    ASSERT_TRUE(runtime->has_pose());
    for (const hal::CanFrame& frame : host_frames()) {
      protocol::PosePositionZ z;
      if (protocol::decode(frame, z) == protocol::DecodeStatus::ok) {
        pose_cycles.push_back(cycle);
        pose_sequences.push_back(z.sequence);
      }
      protocol::PoseUncertainty u;
      if (protocol::decode(frame, u) == protocol::DecodeStatus::ok) {
        radii_cycles.push_back(cycle);
        radii_sequences.push_back(u.sequence);
      }
      protocol::Status status;
      if (protocol::decode(frame, status) == protocol::DecodeStatus::ok) ++status_frames;
    }
  }
  ASSERT_EQ(pose_cycles.size(), 25u);
  for (std::size_t i = 1; i < pose_cycles.size(); ++i) EXPECT_EQ(pose_cycles[i] - pose_cycles[i - 1], 4);
  ASSERT_EQ(radii_cycles.size(), 5u);  // begun in cycles 1, 21, 41, 61 and 81
  for (std::size_t i = 1; i < radii_cycles.size(); ++i) EXPECT_EQ(radii_cycles[i] - radii_cycles[i - 1], 20);
  for (const std::uint8_t sequence : radii_sequences) {
    EXPECT_NE(std::find(pose_sequences.begin(), pose_sequences.end(), sequence), pose_sequences.end())
        << "radii of a pose that did not go out: " << int(sequence);
  }
  EXPECT_EQ(runtime->statistics().poses_published, 25u);
  EXPECT_EQ(status_frames, 4);  // cycles 25, 50, 75 and 100
}

}  // namespace
}  // namespace cdcr::firmware