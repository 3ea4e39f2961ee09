// The cables' hysteresis on the board, with an image that carries a
// hysteresis block: the state the runtime keeps equals a float32 run of
// model::update_hysteresis over the same cable sets bit for bit, and its
// poses are those of the effective lengths; the state is unknown at
// power-up (STATUS HYSTERESIS_UNKNOWN) until every cable has travelled far
// enough or a HOMING frame arrives; r95 is wider while it is unknown, by the
// covariance the effective lengths' uncertainty gives the tip; and without a
// hysteresis block nothing of this shows.

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "cdcr/model/compensated_kinematics.hpp"
#include "cdcr/model/image_hysteresis.hpp"
#include "cdcr/model/pose_error_summary.hpp"
#include "runtime_test_fixture.hpp"
#include "train/evaluation.hpp"
#include "train/predictive_variance.hpp"
#include "../support/synthetic_trained_model.hpp"
#include "../support/variance_block.hpp"

#include "../support/image_in_double.hpp"

namespace cdcr::firmware {
namespace {

namespace protocol = firmware::protocol;
using test_support::RuntimeTest;

// The fixture's small model (two segments) with two play operators per
// cable, and a variance block of `rank` points if rank > 0.
training::TrainedModel hysteresis_model(int rank = 0) {
  training::TrainedModel m = test_support::small_correction_model(rank > 0 ? 200 : 5);
  std::mt19937 rng(11);
  m.hysteresis = test_support::synthetic_hysteresis(m.geometry, 2, rng);
  if (rank > 0) test_support::add_variance_block(m, rank);
  return m;
}

class RuntimeHysteresisTest : public RuntimeTest {
 protected:
  void boot_with(const training::TrainedModel& m) {
    image = exporting::write_image(m);
    boot(image);
    ASSERT_EQ(runtime->state(), RuntimeState::run);
    drives->set_silent(true);  // the test gives the drives' lengths itself
    model::ImageView view{};
    ASSERT_EQ(model::parse_image(image.data(), image.size(), view), model::ImageStatus::ok);
    model::hysteresis_from_image(view, host_model);
  }

  // One cycle with the drives' lengths `cables_mm`, as the feedback frames
  // carry them; returns them as the runtime received them.
  Cables cycle_at(const model::CableVector<double, kMaxSegments>& cables_mm) {
    last_cables_mm = cables_mm;
    Cables received(cables_mm.size());
    for (int s = 0; s < cables_mm.size() / 4; ++s) {
      Scalar lengths[4];
      for (int k = 0; k < 4; ++k) {
        lengths[k] = Scalar(protocol::cable_length_as_transmitted(cables_mm[4 * s + k]));
        received[4 * s + k] = lengths[k];
      }
      EXPECT_TRUE(runtime->set_cable_lengths(s, lengths));
    }
    cycles(1);
    return received;
  }

  model::CableVector<double, kMaxSegments> cables_at(double alpha_rad, double theta_rad) const {
    model::RobotGeometry<double> g = model::RobotGeometry<double>::uniform(2, 120.0, 67.0);
    for (int s = 0; s < 2; ++s) {
      g.segments[s] = {double(runtime->geometry().segments[s].backbone_length_mm),
                       double(runtime->geometry().segments[s].anchor_radius_mm),
                       double(runtime->geometry().segments[s].theta_max_rad)};
    }
    model::JointVector<double> joints(4);
    joints << alpha_rad, theta_rad, -0.5 * alpha_rad, 0.7 * theta_rad;
    model::CableVector<double> cables;
    EXPECT_EQ(model::cables_from_joints(joints, g, cables), model::Status::ok);
    return cables;
  }

  // The next STATUS frame's flag, the drives holding their lengths.
  bool status_says_unknown() {
    host_frames();
    protocol::Status status;
    for (int i = 0; i < kStatusEveryCycles; ++i) {
      cycle_at(last_cables_mm);
      if (last_of(host_frames(), status)) return status.hysteresis_unknown;
    }
    ADD_FAILURE() << "no STATUS frame";
    return false;
  }

  std::vector<std::uint8_t> image;
  model::CableVector<double, kMaxSegments> last_cables_mm;
  model::HysteresisModel<float> host_model;
};

bool same_bits(const model::HysteresisState<float>& a, const model::HysteresisState<float>& b) {
  return a.cables == b.cables && a.operators == b.operators && a.has_position == b.has_position &&
         std::memcmp(a.commanded_mm, b.commanded_mm, sizeof(a.commanded_mm)) == 0 &&
         std::memcmp(a.lag_low_mm, b.lag_low_mm, sizeof(a.lag_low_mm)) == 0 &&
         std::memcmp(a.lag_high_mm, b.lag_high_mm, sizeof(a.lag_high_mm)) == 0;
}

TEST_F(RuntimeHysteresisTest, TheBoardsStateIsAFloat32RunOfTheModelBitForBit) {
  boot_with(hysteresis_model());
  ASSERT_TRUE(runtime->hysteresis().active());
  model::HysteresisState<float> host;
  model::reset_unknown(host, host_model);
  // A path with reversals: straight lines in joint space between random
  // bends, a few cycles each, so every cable moves both ways, by less and
  // by more than its operators' widths.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> alpha(-3.0, 3.0), theta(0.02, 0.3);
  double a0 = 0.3, t0 = 0.1;
  int compared = 0;
  for (int leg = 0; leg < 40; ++leg) {
    const double a1 = alpha(rng), t1 = leg % 3 == 0 ? t0 + 0.004 : theta(rng);
    for (int step = 1; step <= 5; ++step) {
      const double f = step / 5.0;
      const Cables received = cycle_at(cables_at(a0 + f * (a1 - a0), t0 + f * (t1 - t0)));
      model::update_hysteresis(host, host_model, received);
      ASSERT_TRUE(same_bits(runtime->hysteresis().state(), host)) << "leg " << leg << " step " << step;
      // The pose is the one of the effective lengths.
      Cables effective;
      model::effective_lengths(host, host_model, effective);
      PoseEstimate expected;
      ASSERT_EQ(runtime->estimate_pose(effective, expected), model::Status::ok);
      ASSERT_TRUE(runtime->latest_pose().pose.position_mm == expected.pose.position_mm);
      ASSERT_TRUE(runtime->latest_pose().joints == expected.joints);
      ++compared;
    }
    a0 = a1;
    t0 = t1;
  }
  EXPECT_EQ(compared, 200);
  EXPECT_TRUE(runtime->hysteresis().known());
  // The effective lengths are not the drives' (the pose differs from the
  // joints-only one by the lags).
  PoseEstimate commanded;
  ASSERT_EQ(runtime->estimate_pose(Cables(Eigen::Map<const Eigen::VectorXf>(host.commanded_mm, 8)), commanded),
            model::Status::ok);
  EXPECT_GT((commanded.pose.position_mm - runtime->latest_pose().pose.position_mm).norm(), 0.05f);
}

TEST_F(RuntimeHysteresisTest, UnknownAtPowerUpUntilEveryCableHasTravelledFarEnough) {
  boot_with(hysteresis_model());
  cycle_at(cables_at(0.2, 0.1));
  EXPECT_FALSE(runtime->hysteresis().known());
  EXPECT_TRUE(status_says_unknown());
  // A small move: not far enough for any cable.
  cycle_at(cables_at(0.2, 0.1005));
  EXPECT_TRUE(status_says_unknown());
  // A move of every cable by many widths one way, then still.
  cycle_at(cables_at(2.0, 0.3));
  EXPECT_TRUE(runtime->hysteresis().known());
  EXPECT_FALSE(status_says_unknown());
  // It stays known, whichever way the cables go next.
  cycle_at(cables_at(1.9, 0.29));
  EXPECT_FALSE(status_says_unknown());
}

TEST_F(RuntimeHysteresisTest, AHomingFrameMakesTheStateTheImagesHomingState) {
  boot_with(hysteresis_model());
  cycle_at(cables_at(0.0, 0.0));
  ASSERT_TRUE(status_says_unknown());
  send_frame(protocol::Homing{});
  const Cables home = cycle_at(cables_at(0.0, 0.0));
  EXPECT_TRUE(runtime->hysteresis().known());
  EXPECT_FALSE(status_says_unknown());
  model::HysteresisState<float> host;
  ASSERT_EQ(model::start_at_home(host, host_model, runtime->geometry()), model::Status::ok);
  model::update_hysteresis(host, host_model, home);
  EXPECT_TRUE(same_bits(runtime->hysteresis().state(), host));

  // A HOMING frame that does not decode changes nothing and is reported.
  boot_with(hysteresis_model());
  cycle_at(cables_at(0.0, 0.0));
  hal::CanFrame bad;
  protocol::encode(protocol::Homing{}, bad);
  bad.data[0] = 0;  // AT_HOME must be 1
  send(bad);
  cycle_at(cables_at(0.0, 0.0));
  EXPECT_FALSE(runtime->hysteresis().known());
  EXPECT_EQ(runtime->last_event(), FaultCode::homing_malformed);
}

TEST_F(RuntimeHysteresisTest, WithoutAHysteresisBlockNothingChanges) {
  training::TrainedModel m = hysteresis_model();
  m.hysteresis = model::HysteresisModel<double>{};
  boot_with(m);
  EXPECT_FALSE(runtime->hysteresis().active());
  const Cables received = cycle_at(cables_at(0.4, 0.2));
  EXPECT_FALSE(status_says_unknown());
  PoseEstimate expected;
  ASSERT_EQ(runtime->estimate_pose(received, expected), model::Status::ok);
  EXPECT_TRUE(runtime->latest_pose().pose.position_mm == expected.pose.position_mm);
  send_frame(protocol::Homing{});  // accepted, and nothing to do
  cycle_at(cables_at(0.4, 0.2));
  EXPECT_EQ(runtime->last_event(), FaultCode::none);
}

// The image's path in float32 on the board (state, effective lengths, the
// compensated pose) against the same in double: the trainer's hysteresis
// model in double, and the image's GP in double, with the state carried from
// home over 200 rows that move every cable both ways.
TEST_F(RuntimeHysteresisTest, Float32FidelityOverTwoHundredRowsAgainstDouble) {
  const training::TrainedModel m = hysteresis_model();
  boot_with(m);
  test_support::ImageInDouble reference;
  ASSERT_TRUE(test_support::read_image_in_double(image, reference));
  const model::RobotGeometry<double>& geometry = reference.geometry;
  model::HysteresisState<double> state;
  ASSERT_EQ(model::start_at_home(state, m.hysteresis, geometry), model::Status::ok);
  send_frame(protocol::Homing{});

  std::mt19937 rng(23);
  std::uniform_real_distribution<double> alpha(-3.0, 3.0), theta(0.02, 0.25), jitter(-0.003, 0.003);
  double a = 0.0, t = 0.0, worst_mm = 0.0, worst_deg = 0.0, largest_lag_effect_mm = 0.0;
  for (int row = 0; row < 200; ++row) {
    if (row % 10 == 0) {
      a = alpha(rng);
      t = theta(rng);
    } else {
      t = std::max(0.0, t + jitter(rng));  // small moves both ways: inside the operators' play
    }
    const Cables received = cycle_at(cables_at(a, t));
    ASSERT_TRUE(runtime->hysteresis().known());
    const model::CableVector<double> commanded = received.cast<double>();
    model::update_hysteresis(state, m.hysteresis, commanded);
    model::CableVector<double> effective;
    model::effective_lengths(state, m.hysteresis, effective);
    largest_lag_effect_mm = std::max(largest_lag_effect_mm, (effective - commanded).cwiseAbs().maxCoeff());
    model::ForwardResult<double> expected;
    ASSERT_EQ(model::compensated_forward(effective, geometry, reference.correction, expected), model::Status::ok);
    const model::Pose<double> board = runtime->latest_pose().pose.cast<double>();
    const model::PoseError<double> e = model::pose_error(expected.compensated, board);
    worst_mm = std::max(worst_mm, e.position_mm);
    worst_deg = std::max(worst_deg, e.orientation_rad * model::kDegreesPerRadian);
  }
  EXPECT_LE(worst_mm, 0.01);
  EXPECT_LE(worst_deg, 0.001);
  EXPECT_GT(largest_lag_effect_mm, 0.2) << "the hysteresis must matter on this path";
}

// r95 while the state is unknown, against the same radii computed here in
// double: the GP's covariance as gp_uncertainty.hpp forms it, plus the
// effective lengths' errors taken to the tip by central differences of the
// runtime's own forward path. The errors enter through the differences of
// opposite cables (l3 - l1, l2 - l4), each with the largest variance its
// bound allows: (u_a + u_b)^2.
TEST_F(RuntimeHysteresisTest, R95IsWiderWhileTheStateIsUnknownByTheCablesUncertainty) {
  const training::TrainedModel m = hysteresis_model(32);
  boot_with(m);
  const hal::CanFilter host_filters[] = {protocol::kPoseFrames, protocol::kStatusFrames};
  platform->host_node.set_filters(host_filters, 2);
  const auto still = cables_at(0.5, 0.12);
  const auto radii_now = [&] {
    std::vector<protocol::PoseUncertainty> radii;
    for (int i = 0; i < 40; ++i) {
      cycle_at(still);
      for (const hal::CanFrame& frame : host_frames()) {
        protocol::PoseUncertainty u;
        if (protocol::decode(frame, u) == protocol::DecodeStatus::ok) radii.push_back(u);
      }
    }
    EXPECT_GE(radii.size(), 3u);
    return radii.back();
  };
  const protocol::PoseUncertainty unknown = radii_now();
  ASSERT_FALSE(runtime->hysteresis().known());
  const PoseEstimate pose = runtime->latest_pose();
  const model::PoseUncertainty<Scalar> gp_only = runtime->estimate_uncertainty(pose);
  ASSERT_GT(gp_only.r95_mm, 0.0f);

  // Expected: the GP's covariance at the tip, plus the cables'.
  model::ImageView view{};
  ASSERT_EQ(model::parse_image(image.data(), image.size(), view), model::ImageStatus::ok);
  const double normalised = view.signal_variance[0] * double(gp_only.latent_share) + view.noise_variance[0];
  Eigen::Matrix3d gp_position = Eigen::Matrix3d::Zero(), gp_rotation = Eigen::Matrix3d::Zero();
  const double ps = view.variance_calibration[model::image_variance_field::position_scale];
  const double os = view.variance_calibration[model::image_variance_field::orientation_scale];
  Eigen::Matrix3d p_hat;
  const Eigen::Vector3d p = pose.pose.position_mm.cast<double>();
  p_hat << 0, -p.z(), p.y(), p.z(), 0, -p.x(), -p.y(), p.x(), 0;
  for (int k = 0; k < 3; ++k) {
    gp_position(k, k) = double(view.output_scale[k]) * view.output_scale[k] * normalised;
    gp_rotation(k, k) = double(view.output_scale[3 + k]) * view.output_scale[3 + k] * normalised;
  }
  gp_position = ps * ps * (gp_position + p_hat * gp_rotation * p_hat.transpose());
  gp_rotation *= os * os;
  Eigen::Matrix3d cable_position = Eigen::Matrix3d::Zero(), cable_rotation = Eigen::Matrix3d::Zero();
  Cables effective;
  model::effective_lengths(runtime->hysteresis().state(), host_model, effective);
  const Cables& u = runtime->hysteresis().uncertainty_mm();
  constexpr float kStepMm = 0.05f;
  for (int c = 0; c < 8; ++c) ASSERT_GT(u[c], 0.0f);
  // Per segment the pairs (l1, l3) and (l2, l4): their difference moves by
  // 2 kStepMm either way (4 kStepMm from minus to plus), their mean stays.
  const int pairs[4][2] = {{0, 2}, {1, 3}, {4, 6}, {5, 7}};
  for (const auto& pair : pairs) {
    const int a = pair[0], b = pair[1];
    Cables plus = effective, minus = effective;
    plus[b] += kStepMm;
    plus[a] -= kStepMm;
    minus[b] -= kStepMm;
    minus[a] += kStepMm;
    PoseEstimate up, down;
    ASSERT_EQ(runtime->estimate_pose(plus, up), model::Status::ok);
    ASSERT_EQ(runtime->estimate_pose(minus, down), model::Status::ok);
    const Eigen::Vector3d dp = (up.pose.position_mm - down.pose.position_mm).cast<double>() / (4.0 * kStepMm);
    const Eigen::Matrix3d dr = (up.pose.rotation * down.pose.rotation.transpose()).cast<double>();
    const Eigen::Vector3d dw = Eigen::Vector3d(dr(2, 1) - dr(1, 2), dr(0, 2) - dr(2, 0), dr(1, 0) - dr(0, 1)) /
                               (2.0 * 4.0 * kStepMm);
    const double variance = (double(u[a]) + u[b]) * (double(u[a]) + u[b]);
    cable_position += variance * dp * dp.transpose();
    cable_rotation += variance * dw * dw.transpose();
  }
  const auto radius = [](const Eigen::Matrix3d& s) { return model::gaussian_radius_95(s.trace(), (s * s).trace()); };
  const double expected_mm = radius(gp_position + cable_position);
  const double expected_deg = radius(gp_rotation + cable_rotation) * model::kDegreesPerRadian;
  EXPECT_NEAR(unknown.r95_position_mm, expected_mm, 0.03 * expected_mm + 0.001);
  EXPECT_NEAR(unknown.r95_orientation_deg, expected_deg, 0.03 * expected_deg + 0.001);
  EXPECT_GT(unknown.r95_position_mm, 1.5 * gp_only.r95_mm);

  // Once known (a HOMING frame), the radii are the GP's own again.
  send_frame(protocol::Homing{});
  const protocol::PoseUncertainty known = radii_now();
  ASSERT_TRUE(runtime->hysteresis().known());
  const model::PoseUncertainty<Scalar> gp_known = runtime->estimate_uncertainty(runtime->latest_pose());
  EXPECT_NEAR(known.r95_position_mm, gp_known.r95_mm, 0.0006);
  EXPECT_NEAR(known.r95_orientation_deg, gp_known.r95_deg, 0.0006);
  EXPECT_LT(known.r95_position_mm, unknown.r95_position_mm);
}

// IK with the cables' hysteresis: the solver finds the effective lengths
// that reach the target, and the setpoints are the commanded lengths that
// produce them from the state the drives' moves leave. The same target,
// approached from either side, is reached both times (the runtime's pose on
// the effective lengths of the drives' lengths, its own model), with
// setpoints that differ by the play the cables take up on the way.
TEST_F(RuntimeHysteresisTest, IkReachesATargetApproachedFromEitherSide) {
  boot_with(hysteresis_model());
  drives->set_silent(false);
  cycles(2);
  send_frame(protocol::Homing{});
  cycles(2);
  ASSERT_TRUE(runtime->hysteresis().known());
  const model::Pose<double> start = runtime->latest_pose().pose.cast<double>();
  const Eigen::Vector3d target = start.position_mm + Eigen::Vector3d(1.0, -3.0, 0.0);
  std::uint8_t sequence = 1;
  // A position target, then cycles until IK is done and the drives hold
  // the setpoints; returns the tip's distance from the target.
  const auto go_to = [&](const Eigen::Vector3d& p) {
    send_position_target(p.x(), p.y(), p.z(), sequence++);
    cycles_until_ik_done();
    protocol::IkReport report;
    EXPECT_TRUE(last_ik_report(report));
    EXPECT_EQ(report.outcome, protocol::IkOutcome::converged)
        << model::to_string(runtime->last_ik_report().model_status) << " iterations " << report.iterations << " residual "
        << report.position_residual_mm;
    int settling = 0;
    do {
      cycles(1);
    } while (++settling < 2000 && (drives->cables_mm() - drives->setpoints_mm()).cwiseAbs().maxCoeff() > 1e-9);
    cycles(3);
    return (runtime->latest_pose().pose.position_mm.cast<double>() - p).norm();
  };
  const Eigen::Vector3d step(3.0, 0.0, 0.0);
  EXPECT_LT(go_to(target - step), 0.05);
  EXPECT_LT(go_to(target), 0.05) << "approached from -x";
  const Cables from_below = runtime->setpoints_mm();
  EXPECT_LT(go_to(target + step), 0.05);
  EXPECT_LT(go_to(target), 0.05) << "approached from +x";
  const Cables from_above = runtime->setpoints_mm();
  // The same effective lengths, commanded differently from either side.
  EXPECT_GT((from_below - from_above).cwiseAbs().maxCoeff(), 0.1f);
}

// An image with the history inputs: after every cable set the runtime holds
// where each cable last moved, read from the tracker's state (the block's
// last operator, 0 while unknown), and its pose is the image's float32 path
// given those inputs (training::firmware_poses, the trainer's check of the
// image); the inputs matter, so a runtime that did not hold them would not
// give it.
TEST_F(RuntimeHysteresisTest, TheTrackersHistoryIsTheCorrectionsHistoryInputs) {
  test_support::SyntheticModelOptions o;
  o.hysteresis_operators = 2;
  o.history = true;
  o.training_points = 12;
  boot_with(test_support::synthetic_trained_model(o));
  ASSERT_TRUE(runtime->correction().takes_history());
  model::ImageView view{};
  ASSERT_EQ(model::parse_image(image.data(), image.size(), view), model::ImageStatus::ok);
  model::HysteresisState<float> host;
  model::reset_unknown(host, host_model);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> alpha(-3.0, 3.0), theta(0.02, 0.3);
  double largest_effect_mm = 0.0;
  bool saw_unknown = false, saw_known = false;
  for (int leg = 0; leg < 12; ++leg) {
    const Cables received = cycle_at(cables_at(alpha(rng), theta(rng)));
    model::update_hysteresis(host, host_model, received);
    Cables effective;
    model::effective_lengths(host, host_model, effective);
    Eigen::MatrixXd history(1, 8);
    float values[8];
    model::history_inputs(host, host_model, values);
    for (int c = 0; c < 8; ++c) history(0, c) = values[c];
    (host.known() ? saw_known : saw_unknown) = true;
    const Eigen::MatrixXd rows = effective.cast<double>().transpose();
    const model::Pose<double> expected =
        training::firmware_poses(view, rows, training::FirmwareAccumulator::float64, {}, history).front();
    ASSERT_LT((runtime->latest_pose().pose.position_mm.cast<double>() - expected.position_mm).norm(), 1e-4)
        << "leg " << leg;
    const model::Pose<double> without =
        training::firmware_poses(view, rows, training::FirmwareAccumulator::float64, {},
                                 Eigen::MatrixXd::Zero(1, 8))
            .front();
    largest_effect_mm = std::max(largest_effect_mm, (without.position_mm - expected.position_mm).norm());
  }
  EXPECT_TRUE(saw_unknown);
  EXPECT_TRUE(saw_known);
  EXPECT_GT(largest_effect_mm, 0.01);
}

}  // namespace
}  // namespace cdcr::firmware
