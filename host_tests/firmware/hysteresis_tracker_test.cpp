// The hysteresis tracker on its own: a model image whose every cable has two
// play operators of widths 0.5 and 0.25 mm and weights 0.5 and 0.25, so
// every lag, effective length and uncertainty below is a short sum worked
// out by hand (and exact in float32). The state must stay unknown until
// each cable has travelled twice its widest play (1 mm) in one direction.

#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/firmware/hysteresis_tracker.hpp>

#include "../support/synthetic_image.hpp"

namespace cdcr::firmware {
namespace {

constexpr int kSegments = 2;
constexpr int kCables = 4 * kSegments;
constexpr float kWideMm = 0.5f, kWideWeight = 0.5f;
constexpr float kNarrowMm = 0.25f, kNarrowWeight = 0.25f;
// Homing lags of our choosing (the check asks only |lag| <= width).
constexpr float kWideHomingLagMm = 0.5f, kNarrowHomingLagMm = -0.25f;

std::vector<std::uint8_t> image_with_play(bool cable_residuals = false) {
  test_support::SyntheticModelOptions options;
  options.cable_residuals = cable_residuals;
  training::TrainedModel trained = test_support::synthetic_trained_model(options);
  model::HysteresisModel<double>& h = trained.hysteresis;
  h.cables = kCables;
  h.operators = 2;
  for (int c = 0; c < kCables; ++c) {
    h.widths_mm[c][0] = kWideMm;
    h.weights[c][0] = kWideWeight;
    h.homing_lag_mm[c][0] = kWideHomingLagMm;
    h.widths_mm[c][1] = kNarrowMm;
    h.weights[c][1] = kNarrowWeight;
    h.homing_lag_mm[c][1] = kNarrowHomingLagMm;
  }
  return exporting::write_image(trained);
}

class HysteresisTrackerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(model::parse_image(image.data(), image.size(), robot.image), model::ImageStatus::ok);
    ASSERT_EQ(model::geometry_from_image(robot.image, robot.geometry), model::Status::ok);
    robot.compensated = true;
    tracker.bind(robot);
    ASSERT_TRUE(tracker.active());
  }

  // Every cable at `base_mm`, cable `moved` (all: -1) `shift_mm` further.
  const Cables& track_at(float base_mm, float shift_mm = 0.0f, int moved = -1) {
    Cables lengths = Cables::Constant(kCables, base_mm);
    for (int c = 0; c < kCables; ++c) {
      if (moved < 0 || c == moved) lengths[c] += shift_mm;
    }
    latest = lengths;
    return tracker.track(latest);
  }

  std::vector<std::uint8_t> image = image_with_play();
  RobotModel robot;
  HysteresisTracker tracker;
  Cables latest;
};

TEST_F(HysteresisTrackerTest, AtPowerUpEveryLagIsUnknownWithinItsWidth) {
  EXPECT_FALSE(tracker.known());
  const Cables effective = track_at(100.0f);
  // The lag intervals are [-r, r]: midpoints 0, half-widths w r summed.
  for (int c = 0; c < kCables; ++c) {
    EXPECT_FLOAT_EQ(effective[c], 100.0f);
    EXPECT_FLOAT_EQ(tracker.uncertainty_mm()[c], kWideWeight * kWideMm + kNarrowWeight * kNarrowMm);
  }
}

TEST_F(HysteresisTrackerTest, OnceTheWidestPlayIsNotEnoughTwiceIs) {
  track_at(100.0f);
  // 0.5 mm: the narrow lag saturates at 0.25; the wide one's interval is
  // [0, 0.5], midpoint 0.25, half-width 0.25.
  Cables effective = track_at(100.0f, kWideMm);
  EXPECT_FALSE(tracker.known());
  for (int c = 0; c < kCables; ++c) {
    EXPECT_FLOAT_EQ(effective[c], 100.5f - (0.5f * 0.25f + 0.25f * 0.25f));
    EXPECT_FLOAT_EQ(tracker.uncertainty_mm()[c], 0.5f * 0.25f);
  }
  track_at(100.0f, 0.99f);
  EXPECT_FALSE(tracker.known());
  // 1 mm: both lags at +r.
  effective = track_at(100.0f, 2.0f * kWideMm);
  EXPECT_TRUE(tracker.known());
  for (int c = 0; c < kCables; ++c) {
    EXPECT_FLOAT_EQ(effective[c], 101.0f - (0.5f * 0.5f + 0.25f * 0.25f));
    EXPECT_EQ(tracker.uncertainty_mm()[c], 0.0f);
  }
}

TEST_F(HysteresisTrackerTest, ShorteningNeedsTwiceTheWidestPlayToo) {
  track_at(100.0f);
  track_at(100.0f, -kWideMm);
  EXPECT_FALSE(tracker.known());
  const Cables effective = track_at(100.0f, -2.0f * kWideMm);
  EXPECT_TRUE(tracker.known());
  for (int c = 0; c < kCables; ++c) EXPECT_FLOAT_EQ(effective[c], 99.0f + (0.5f * 0.5f + 0.25f * 0.25f));
}

TEST_F(HysteresisTrackerTest, OneCableShortOfTwiceItsPlayKeepsTheStateUnknown) {
  track_at(100.0f);
  track_at(101.0f, -kWideMm, 3);  // cable 3 only half way
  EXPECT_FALSE(tracker.known());
  for (int c = 0; c < kCables; ++c) EXPECT_FLOAT_EQ(tracker.uncertainty_mm()[c], c == 3 ? 0.5f * 0.25f : 0.0f);
  track_at(101.0f);
  EXPECT_TRUE(tracker.known());
  // Known stays known: a reversal moves the lags but opens no interval.
  track_at(100.0f);
  EXPECT_TRUE(tracker.known());
}

TEST_F(HysteresisTrackerTest, HomingMakesTheStateKnownAtTheHomingLags) {
  tracker.homed(robot.geometry);
  EXPECT_TRUE(tracker.known());
  // Home is the straight robot: every cable at its backbone's length. From
  // there 0.125 mm longer: the wide lag stays at its +0.5 bound, the narrow
  // one moves from -0.25 to -0.125.
  const float backbone_mm[kSegments] = {robot.geometry.segments[0].backbone_length_mm,
                                        robot.geometry.segments[1].backbone_length_mm};
  Cables lengths(kCables);
  for (int c = 0; c < kCables; ++c) lengths[c] = backbone_mm[c / 4] + 0.125f;
  const Cables effective = tracker.track(lengths);
  for (int c = 0; c < kCables; ++c) {
    EXPECT_NEAR(effective[c], lengths[c] - (0.5f * 0.5f + 0.25f * -0.125f), 1e-5f) << "cable " << c;
    EXPECT_EQ(tracker.uncertainty_mm()[c], 0.0f);
  }
}

TEST_F(HysteresisTrackerTest, SetpointsInvertThePlayAfterAReversal) {
  track_at(100.0f);
  track_at(102.0f);  // every lag at +r, effective 102 - 0.3125
  // Further out, all saturated: slope 1.
  Cables setpoints = Cables::Constant(kCables, 102.0f);
  tracker.commanded_for(setpoints);
  for (int c = 0; c < kCables; ++c) EXPECT_FLOAT_EQ(setpoints[c], 102.0f + 0.3125f);
  // Back 0.1 mm: both lags leave their bound, slope 1 - 0.75 until the
  // narrow one saturates after 0.5 mm, so 0.4 mm of command.
  setpoints = Cables::Constant(kCables, 102.0f - 0.3125f - 0.1f);
  tracker.commanded_for(setpoints);
  for (int c = 0; c < kCables; ++c) EXPECT_NEAR(setpoints[c], 102.0f - 0.4f, 1e-5f);
}

TEST_F(HysteresisTrackerTest, LengthsThatAreNotFiniteLeaveTheStateAlone) {
  track_at(100.0f);
  const Cables before = tracker.uncertainty_mm();
  Cables lengths = Cables::Constant(kCables, 101.0f);
  lengths[2] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(&tracker.track(lengths), &lengths);
  EXPECT_FALSE(tracker.known());
  EXPECT_EQ(tracker.state().commanded_mm[0], 100.0f);
  EXPECT_EQ(tracker.uncertainty_mm(), before);
}

// The robot of `image` as the runtime binds it, and a tracker bound to it.
void bind_robot(const std::vector<std::uint8_t>& image, bool compensated, RobotModel& robot,
                HysteresisTracker& tracker) {
  ASSERT_EQ(model::parse_image(image.data(), image.size(), robot.image), model::ImageStatus::ok);
  ASSERT_EQ(model::geometry_from_image(robot.image, robot.geometry), model::Status::ok);
  robot.compensated = compensated;
  tracker.bind(robot);
}

TEST(HysteresisTrackerWithoutPlay, AnUncompensatedModelLeavesTheLengthsAlone) {
  const std::vector<std::uint8_t> image = image_with_play();
  RobotModel robot;
  HysteresisTracker tracker;
  ASSERT_NO_FATAL_FAILURE(bind_robot(image, false, robot, tracker));
  EXPECT_FALSE(tracker.active());
  EXPECT_TRUE(tracker.known());
  EXPECT_EQ(hysteresis_units(tracker), 0u);
  const Cables lengths = Cables::Constant(kCables, 100.0f);
  EXPECT_EQ(&tracker.track(lengths), &lengths);
  Cables setpoints = lengths;
  tracker.commanded_for(setpoints);
  EXPECT_EQ(setpoints, lengths);
}

// Cables beyond the bend limit: a joints-only model needs them pulled
// within it (the runtime would refuse them), a model that takes the
// cables' residuals reads them as the trainer did, unchanged.
TEST(HysteresisTrackerLimit, OnlyAModelThatCannotReadBeyondTheLimitIsPulledWithinIt) {
  for (const bool cable_residuals : {false, true}) {
    SCOPED_TRACE(cable_residuals ? "cable-fit model" : "joints-only model");
    const std::vector<std::uint8_t> image = image_with_play(cable_residuals);
    RobotModel robot;
    HysteresisTracker tracker;
    ASSERT_NO_FATAL_FAILURE(bind_robot(image, true, robot, tracker));
    ASSERT_TRUE(tracker.active());
    // Segment 1 bent twice as far as its chord allows, along l3 - l1; at
    // power-up the lags' midpoints are 0, so the effective lengths are the
    // commanded ones but for the pull.
    const model::SegmentGeometry<float>& g = robot.geometry.segments[0];
    const float limit = 4.0f * g.anchor_radius_mm * std::sin(0.5f * g.theta_max_rad);
    Cables commanded = Cables::Constant(kCables, 100.0f);
    commanded[0] = 100.0f - limit;
    commanded[2] = 100.0f + limit;
    const Cables effective = tracker.track(commanded);
    if (cable_residuals) {
      EXPECT_EQ(effective, commanded);
    } else {
      EXPECT_NEAR(effective[2] - effective[0], limit, 1e-3f * limit);
      EXPECT_FLOAT_EQ(effective[0] + effective[2], 200.0f);
      for (int c = 4; c < kCables; ++c) EXPECT_EQ(effective[c], commanded[c]);
    }
  }
}

// The same with three cables a segment at 0, -120 and 120 degrees: the
// chord D = -(4/3) sum_j l_j e_j (eq. (2) fitted to three anchors) shrinks
// to the limit along itself, the cables' mean stays.
TEST(HysteresisTrackerLimit, ThreeCablesArePulledWithinTheLimitAlongTheirChord) {
  test_support::SyntheticModelOptions options;
  options.cables_per_segment = 3;
  options.hysteresis_operators = 1;
  const std::vector<std::uint8_t> image = exporting::write_image(test_support::synthetic_trained_model(options));
  RobotModel robot;
  HysteresisTracker tracker;
  ASSERT_NO_FATAL_FAILURE(bind_robot(image, true, robot, tracker));
  ASSERT_TRUE(tracker.active());
  ASSERT_EQ(robot.geometry.cable_count(), 6);
  const model::SegmentGeometry<float>& g = robot.geometry.segments[0];
  const float limit = 4.0f * g.anchor_radius_mm * std::sin(0.5f * g.theta_max_rad);
  // Twice the limit towards cable 2's anchor, at -120 degrees.
  Cables commanded = Cables::Constant(6, 100.0f);
  commanded[0] = 100.0f + 0.5f * limit;
  commanded[1] = 100.0f - limit;
  commanded[2] = 100.0f + 0.5f * limit;
  const Cables effective = tracker.track(commanded);
  const float half_root3 = 0.5f * std::sqrt(3.0f);
  const float chord_x = -(4.0f / 3.0f) * (effective[0] - 0.5f * effective[1] - 0.5f * effective[2]);
  const float chord_y = -(4.0f / 3.0f) * (-half_root3 * effective[1] + half_root3 * effective[2]);
  EXPECT_NEAR(chord_x, -0.5f * limit, 1e-3f * limit);
  EXPECT_NEAR(chord_y, -half_root3 * limit, 1e-3f * limit);
  EXPECT_NEAR(effective[0] + effective[1] + effective[2], 300.0f, 1e-3f);
  for (int c = 3; c < 6; ++c) EXPECT_EQ(effective[c], commanded[c]);
}

}  // namespace
}  // namespace cdcr::firmware
