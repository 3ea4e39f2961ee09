// The C API (cdcr/cdcr.h) against the C++ runtime it wraps: the same pose
// from the same cable lengths, bit for bit; the paper's Table 1 pose without
// an image; targets solved to setpoints; the states and faults as the
// runtime reports them; and an error code for every argument it cannot use.

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/cdcr.h>
#include <cdcr/firmware/protocol.hpp>
#include <cdcr/firmware/runtime.hpp>

#include "c_api_check.h"
#include "export/image_writer.hpp"
#include "train/predictive_variance.hpp"
#include "../support/variance_block.hpp"
#include "synthetic_trained_model.hpp"

namespace cdcr::firmware {
namespace {

// Corrections of a few tenths of a millimetre, as a trained model makes.
// small_image: with fitted_range_offset, the image's fitted input range is moved that
// far (in every input) from where its points are, so every query is outside.
// With payload_input, the model has the payload as an input.
training::TrainedModel small_model(const test_support::SyntheticModelOptions& options) {
  training::TrainedModel m = test_support::synthetic_trained_model(options);
  for (int k = 0; k < 6; ++k) {
    m.output_mean[k] *= k < 3 ? 0.1 : 0.001;
    m.output_scale[k] *= k < 3 ? 0.1 : 0.001;
  }
  return m;
}

std::vector<std::uint8_t> small_image(int segments = 2, double fitted_range_offset = 0.0, bool payload_input = false) {
  test_support::SyntheticModelOptions options;
  options.segments = segments;
  options.payload_input = payload_input;
  training::TrainedModel m = small_model(options);
  if (fitted_range_offset != 0.0) {
    m.set_input_range(m.inputs);
    m.input_min.array() += fitted_range_offset;
    m.input_max.array() += fitted_range_offset;
  }
  return exporting::write_image(m);
}

// What the runtime makes of the lengths a drive sends in a frame.
Cables as_transmitted(const std::vector<float>& lengths) {
  Cables cables(lengths.size());
  for (std::size_t i = 0; i < lengths.size(); ++i) {
    cables[i] = Scalar(protocol::cable_length_as_transmitted(lengths[i]));
  }
  return cables;
}

// A HAL with nothing on it but the image, for the C++ runtime beside the C one.
struct QuietHal final : hal::MonotonicClock, hal::PeriodicTimer, hal::CanBus, hal::ModelStorage, hal::Console {
  explicit QuietHal(const std::vector<std::uint8_t>& image) : image(image) {}
  std::int64_t now_ns() const override { return 0; }
  void start(std::int64_t) override {}
  hal::TimerTick wait_next() override { return {}; }
  std::int64_t period_ns() const override { return 0; }
  std::uint32_t overruns() const override { return 0; }
  hal::CanStatus send(const hal::CanFrame&) override { return hal::CanStatus::ok; }
  hal::CanStatus receive(hal::CanFrame&) override { return hal::CanStatus::empty; }
  bool set_filters(const hal::CanFilter*, std::size_t) override { return true; }
  hal::CanErrorCounters error_counters() const override { return {}; }
  hal::MemoryRegion model_region() const override { return {image.data(), image.size()}; }
  void write_line(const char*) override {}
  hal::Hal hal() { return hal::Hal{*this, *this, *this, *this, *this}; }
  std::vector<std::uint8_t> image;
};

// Lengths of a bent robot, on the protocol's 0.01 mm steps.
std::vector<float> bent_cables(const Geometry& geometry, double theta_rad = 0.15) {
  model::RobotGeometry<double, kMaxSegments> g = geometry.cast<double>();
  model::JointVector<double, kMaxSegments> joints(2 * g.segment_count);
  for (int s = 0; s < g.segment_count; ++s) {
    joints[2 * s] = 0.7 * (s + 1);
    joints[2 * s + 1] = theta_rad;
  }
  model::CableVector<double, kMaxSegments> cables;
  EXPECT_EQ(model::cables_from_joints(joints, g, cables), model::Status::ok);
  std::vector<float> out;
  for (int i = 0; i < cables.size(); ++i) out.push_back(float(std::round(cables[i] * 100.0) / 100.0));
  return out;
}

// The C API's pose after `cycles` cycles on a bent robot's lengths, and the
// C++ runtime's estimate of the same lengths on the same image beside it.
class CApiPose : public ::testing::Test {
 protected:
  void run_both(const std::vector<std::uint8_t>& image_bytes, int cycles) {
    image = image_bytes;
    platform = std::make_unique<QuietHal>(image);
    runtime = std::make_unique<Runtime>(platform->hal(), Geometry::prototype());
    ASSERT_EQ(runtime->init(), RuntimeState::run);
    const std::vector<float> lengths = bent_cables(runtime->geometry());
    ASSERT_EQ(c_api_check_pose(image.data(), std::uint32_t(image.size()), nullptr, lengths.data(), lengths.size(),
                               cycles, &pose, &status),
              0);
    ASSERT_EQ(runtime->estimate_pose(as_transmitted(lengths), expected), model::Status::ok);
  }

  std::vector<std::uint8_t> image;
  std::unique_ptr<QuietHal> platform;
  std::unique_ptr<Runtime> runtime;
  cdcr_pose pose{};
  cdcr_status status{};
  PoseEstimate expected;
};

TEST_F(CApiPose, PoseFromCableLengthsIsTheRuntimes) {
  ASSERT_NO_FATAL_FAILURE(run_both(small_image(), 3));
  EXPECT_EQ(status.state, CDCR_STATE_RUN);
  EXPECT_EQ(status.fault, CDCR_FAULT_NONE);
  EXPECT_EQ(status.cycles, 3u);
  ASSERT_TRUE(expected.compensated);
  EXPECT_EQ(pose.compensated, 1);
  EXPECT_EQ(pose.segment_count, 2);
  EXPECT_EQ(pose.count, 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(pose.position_mm[i], expected.pose.position_mm[i]) << "position " << i;
    for (int j = 0; j < 3; ++j) EXPECT_EQ(pose.rotation[3 * i + j], expected.pose.rotation(i, j)) << i << "," << j;
  }
  for (int i = 0; i < 4; ++i) EXPECT_EQ(pose.joints[i], expected.joints[i]) << "joint " << i;
  // The quaternion is the rotation's, w >= 0.
  const Eigen::Quaternionf q(pose.quaternion[0], pose.quaternion[1], pose.quaternion[2], pose.quaternion[3]);
  EXPECT_GE(pose.quaternion[0], 0.0f);
  EXPECT_LT((q.toRotationMatrix() - expected.pose.rotation).cwiseAbs().maxCoeff(), 1e-5f);
}

// The radii the runtime computes over a few cycles reach the C side: those
// of the pose, as the same code gives them in one go.
TEST_F(CApiPose, PoseCarriesTheRadiiOfTheImagesVariance) {
  test_support::SyntheticModelOptions options;
  options.segments = 2;
  options.training_points = 40;
  training::TrainedModel m = test_support::synthetic_trained_model(options);
  test_support::add_variance_block(m, 12);
  ASSERT_NO_FATAL_FAILURE(run_both(exporting::write_image(m), 12));
  const model::PoseUncertainty<Scalar> radii = runtime->estimate_uncertainty(expected);
  ASSERT_GT(radii.r95_mm, 0.0f);
  EXPECT_EQ(pose.r95_mm, radii.r95_mm);
  EXPECT_EQ(pose.r95_deg, radii.r95_deg);
  EXPECT_EQ(pose.extrapolating, radii.extrapolating || expected.outside_range ? 1 : 0);
}

// The paper's Table 1, case 2 (L = 120 mm, r = 70 mm): without an image the
// C API gives the nominal pose printed there.
TEST(CApi, NominalPoseWithoutAnImageIsTable1) {
  const float lengths[16] = {118, 123, 124, 115, 124, 115, 118, 121, 110, 117, 125, 123, 124, 105, 112, 128};
  const cdcr_geometry geometry = {4, 120.0f, 70.0f, 1.5707963f, 0};
  cdcr_pose pose{};
  cdcr_status status{};
  ASSERT_EQ(c_api_check_pose(nullptr, 0, &geometry, lengths, 16, 1, &pose, &status), 0);
  EXPECT_EQ(status.state, CDCR_STATE_DEGRADED);
  EXPECT_EQ(status.boot_fault, CDCR_FAULT_IMAGE_MISSING);
  EXPECT_EQ(pose.compensated, 0);
  const float expected[12] = {0.9997f, 0.0125f,  0.0200f, 19.2070f, -0.0084f, 0.9814f,
                              -0.1917f, -6.3962f, -0.0220f, 0.1914f, 0.9813f, 478.3811f};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(pose.position_mm[i], expected[4 * i + 3], 2e-3) << "position " << i;
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(pose.rotation[3 * i + j], expected[4 * i + j], 1e-4) << i << "," << j;
  }
}

class CApiRuntime : public ::testing::Test {
 protected:
  void init(const std::vector<std::uint8_t>& image_bytes) {
    image = image_bytes;
    config = cdcr_config{};
    config.model_image = image.empty() ? nullptr : image.data();
    config.model_image_size = std::uint32_t(image.size());
    config.fallback_geometry = cdcr_geometry{2, 120.0f, 67.0f, 1.5707963f, 0};
    ASSERT_EQ(cdcr_init(&runtime, &config), CDCR_OK);
  }
  void step_with(const std::vector<float>& lengths, int steps = 1) {
    for (int k = 0; k < steps; ++k) {
      ASSERT_EQ(cdcr_set_cable_lengths(&runtime, lengths.data(), lengths.size()), CDCR_OK);
      ASSERT_EQ(cdcr_step(&runtime), CDCR_OK);
    }
  }
  cdcr_status status() {
    cdcr_status s{};
    EXPECT_EQ(cdcr_get_status(&runtime, &s), CDCR_OK);
    return s;
  }

  // A position target a few millimetres from `start`.
  static cdcr_target position_target_near(const cdcr_pose& start, std::uint8_t sequence) {
    cdcr_target target{};
    target.position_mm[0] = start.position_mm[0] + 4.0f;
    target.position_mm[1] = start.position_mm[1] - 3.0f;
    target.position_mm[2] = start.position_mm[2] - 1.0f;
    target.mode = CDCR_TARGET_POSITION;
    target.sequence = sequence;
    return target;
  }
  // Steps at `lengths` while the solver runs, 300 steps at most.
  void step_while_solving(const std::vector<float>& lengths) {
    int steps = 0;
    do {
      step_with(lengths);
    } while (status().ik_running && ++steps < 300);
  }

  // init, and the C++ runtime on the same image beside the C one.
  void init_with_reference(const std::vector<std::uint8_t>& image_bytes) {
    ASSERT_NO_FATAL_FAILURE(init(image_bytes));
    reference_platform = std::make_unique<QuietHal>(image);
    reference = std::make_unique<Runtime>(reference_platform->hal(), Geometry::prototype());
    ASSERT_EQ(reference->init(), RuntimeState::run);
  }

  std::vector<std::uint8_t> image;
  cdcr_config config{};
  cdcr_runtime runtime{};
  std::unique_ptr<QuietHal> reference_platform;
  std::unique_ptr<Runtime> reference;
};

// cdcr_set_payload: a payload model's pose is the runtime's at that payload
// from the next step, and a payload the PAYLOAD frame cannot carry (NaN,
// negative, beyond 50 kg) is refused without changing the one in use.
TEST_F(CApiRuntime, PayloadReachesThePoseAndBadOnesAreRefused) {
  test_support::SyntheticModelOptions options;
  options.payload_input = true;
  ASSERT_NO_FATAL_FAILURE(init_with_reference(exporting::write_image(small_model(options))));
  const std::vector<float> lengths = bent_cables(reference->geometry());
  const Cables cables = as_transmitted(lengths);
  const auto pose_at = [&](float payload_kg) {
    EXPECT_TRUE(reference->set_payload_kg(payload_kg));
    PoseEstimate e;
    EXPECT_EQ(reference->estimate_pose(cables, e), model::Status::ok);
    return e.pose.position_mm;
  };
  step_with(lengths, 2);
  cdcr_pose pose{};
  ASSERT_EQ(cdcr_get_pose(&runtime, &pose), CDCR_OK);
  const model::Vec3<float> at_default = pose_at(0.375f);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(pose.position_mm[i], at_default[i]);

  ASSERT_EQ(cdcr_set_payload(&runtime, 0.75f), CDCR_OK);
  step_with(lengths);
  ASSERT_EQ(cdcr_get_pose(&runtime, &pose), CDCR_OK);
  const model::Vec3<float> loaded = pose_at(0.75f);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(pose.position_mm[i], loaded[i]);
  EXPECT_GT((loaded - at_default).norm(), 1e-3f);

  for (const float bad : {std::nanf(""), -0.5f, 50.5f, INFINITY}) {
    EXPECT_EQ(cdcr_set_payload(&runtime, bad), CDCR_ERROR_OUT_OF_RANGE) << bad;
  }
  step_with(lengths);
  ASSERT_EQ(cdcr_get_pose(&runtime, &pose), CDCR_OK);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(pose.position_mm[i], loaded[i]);
  EXPECT_EQ(cdcr_set_payload(nullptr, 0.5f), CDCR_ERROR_NULL_ARGUMENT);
  EXPECT_STREQ(cdcr_fault_name(CDCR_FAULT_PAYLOAD_INVALID), "payload invalid");
}

// cdcr_homing with an image that models the cables' hysteresis: the state
// is unknown from init (cdcr_status.hysteresis_unknown) until the call, and
// the pose is then the runtime's on the effective lengths from home; without
// a block the call is accepted and changes nothing.
TEST_F(CApiRuntime, HomingMakesTheHysteresisStateKnown) {
  test_support::SyntheticModelOptions options;
  options.hysteresis_operators = 2;
  ASSERT_NO_FATAL_FAILURE(init_with_reference(exporting::write_image(small_model(options))));
  Cables approach, home;
  ASSERT_EQ(model::homing_waypoints(reference->geometry(), approach, home), model::Status::ok);
  const std::vector<float> at_home(home.data(), home.data() + home.size());
  step_with(at_home, 2);
  EXPECT_EQ(status().hysteresis_unknown, 1);
  ASSERT_EQ(cdcr_homing(&runtime), CDCR_OK);
  const std::vector<float> lengths = bent_cables(reference->geometry());
  step_with(lengths);
  EXPECT_EQ(status().hysteresis_unknown, 0);

  // The reference: homed at home, then at the same lengths.
  reference->set_homed();
  const Cables cables = as_transmitted(lengths);
  model::HysteresisState<float> state = reference->hysteresis().state();
  model::update_hysteresis(state, reference->hysteresis().hysteresis_model(), cables);
  Cables effective;
  model::effective_lengths(state, reference->hysteresis().hysteresis_model(), effective);
  PoseEstimate expected;
  ASSERT_EQ(reference->estimate_pose(effective, expected), model::Status::ok);
  cdcr_pose pose{};
  ASSERT_EQ(cdcr_get_pose(&runtime, &pose), CDCR_OK);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(pose.position_mm[i], expected.pose.position_mm[i]);
  EXPECT_EQ(cdcr_homing(nullptr), CDCR_ERROR_NULL_ARGUMENT);

  init(small_image());
  step_with(lengths);
  EXPECT_EQ(status().hysteresis_unknown, 0);
  EXPECT_EQ(cdcr_homing(&runtime), CDCR_OK);
  step_with(lengths);
  EXPECT_EQ(status().fault, CDCR_FAULT_NONE);
}

// A pose target from the C API: solved over steps, setpoints out, and the
// drives at the setpoints put the tip on the target.
TEST_F(CApiRuntime, TargetIsSolvedToSetpoints) {
  init(small_image());
  std::vector<float> lengths = bent_cables(Geometry::uniform(2, 120.0f, 67.0f), 0.1);
  step_with(lengths, 2);
  cdcr_pose start{};
  ASSERT_EQ(cdcr_get_pose(&runtime, &start), CDCR_OK);
  cdcr_setpoints setpoints{};
  EXPECT_EQ(cdcr_get_setpoints(&runtime, &setpoints), CDCR_ERROR_NO_DATA);
  EXPECT_EQ(status().ik_outcome, CDCR_IK_NONE);

  const cdcr_target target = position_target_near(start, 42);
  ASSERT_EQ(cdcr_set_target(&runtime, &target), CDCR_OK);
  step_while_solving(lengths);
  const cdcr_status done = status();
  EXPECT_EQ(done.ik_outcome, CDCR_IK_CONVERGED);
  EXPECT_EQ(done.ik_sequence, 42);
  EXPECT_EQ(done.targets_received, 1u);
  EXPECT_LT(done.ik_position_error_mm, 0.05f);
  ASSERT_EQ(cdcr_get_setpoints(&runtime, &setpoints), CDCR_OK);
  ASSERT_EQ(setpoints.cable_count, 8);
  EXPECT_GE(setpoints.count, 1u);

  lengths.assign(setpoints.lengths_mm, setpoints.lengths_mm + setpoints.cable_count);
  step_with(lengths);
  cdcr_pose reached{};
  ASSERT_EQ(cdcr_get_pose(&runtime, &reached), CDCR_OK);
  // Within the solver's acceptance and the drives' 0.01 mm steps.
  const float distance = std::hypot(reached.position_mm[0] - target.position_mm[0],
                                    reached.position_mm[1] - target.position_mm[1],
                                    reached.position_mm[2] - target.position_mm[2]);
  EXPECT_LT(distance, 0.1f);
}

// A target that refuses extrapolation, on a model whose fitted range holds
// none of the robot's poses: refused, setpoints held.
TEST_F(CApiRuntime, ATargetRefusingExtrapolationIsRefusedOutsideTheFittedRange) {
  for (const int refuse : {0, 1}) {
    SCOPED_TRACE(refuse);
    init(small_image(2, 5.0));
    std::vector<float> lengths = bent_cables(Geometry::uniform(2, 120.0f, 67.0f), 0.1);
    step_with(lengths, 2);
    cdcr_pose start{};
    ASSERT_EQ(cdcr_get_pose(&runtime, &start), CDCR_OK);
    EXPECT_EQ(start.extrapolating, 1);
    cdcr_target target = position_target_near(start, 7);
    target.refuse_extrapolating = refuse;
    ASSERT_EQ(cdcr_set_target(&runtime, &target), CDCR_OK);
    step_while_solving(lengths);
    cdcr_setpoints setpoints{};
    if (refuse) {
      EXPECT_EQ(status().ik_outcome, CDCR_IK_REFUSED_EXTRAPOLATING);
      EXPECT_EQ(cdcr_get_setpoints(&runtime, &setpoints), CDCR_ERROR_NO_DATA);
    } else {
      EXPECT_EQ(status().ik_outcome, CDCR_IK_CONVERGED);
      EXPECT_EQ(cdcr_get_setpoints(&runtime, &setpoints), CDCR_OK);
    }
  }
}

TEST_F(CApiRuntime, SilentDrivesAreAFaultWithNoPose) {
  init(small_image());
  const std::vector<float> lengths = bent_cables(Geometry::uniform(2, 120.0f, 67.0f));
  step_with(lengths);
  cdcr_pose pose{};
  EXPECT_EQ(cdcr_get_pose(&runtime, &pose), CDCR_OK);
  for (int k = 0; k < 12; ++k) ASSERT_EQ(cdcr_step(&runtime), CDCR_OK);
  EXPECT_EQ(status().state, CDCR_STATE_FAULT);
  EXPECT_EQ(status().fault, CDCR_FAULT_CABLE_INPUT_STALE);
  EXPECT_EQ(status().stale_events, 1u);
  EXPECT_EQ(cdcr_get_pose(&runtime, &pose), CDCR_ERROR_NO_DATA);
  step_with(lengths);
  EXPECT_EQ(status().state, CDCR_STATE_RUN);
  EXPECT_EQ(cdcr_get_pose(&runtime, &pose), CDCR_OK);
}

TEST_F(CApiRuntime, DamagedImageIsDegradedWithTheParsersReason) {
  std::vector<std::uint8_t> damaged = small_image();
  damaged[damaged.size() / 2] ^= 0x40;
  init(damaged);
  EXPECT_EQ(status().state, CDCR_STATE_DEGRADED);
  EXPECT_EQ(status().boot_fault, CDCR_FAULT_IMAGE_INVALID);
  EXPECT_EQ(status().fault_detail, std::uint8_t(model::ImageStatus::checksum_mismatch));
  step_with(bent_cables(Geometry::uniform(2, 120.0f, 67.0f)));
  cdcr_pose pose{};
  ASSERT_EQ(cdcr_get_pose(&runtime, &pose), CDCR_OK);
  EXPECT_EQ(pose.compensated, 0);
}

// A board on the CAN protocol: its frames through the callbacks.
struct Bus {
  std::vector<cdcr_can_frame> sent;
  std::vector<cdcr_can_frame> inbox;
  int filters_set = 0;
};

// The board's CAN callbacks on `bus`: what the runtime sends is kept, what
// it receives comes from the inbox, and the filters it sets are counted.
void connect(cdcr_callbacks& callbacks, Bus& bus) {
  callbacks.user = &bus;
  callbacks.can_send = [](void* user, const cdcr_can_frame* frame) {
    static_cast<Bus*>(user)->sent.push_back(*frame);
    return 0;
  };
  callbacks.can_receive = [](void* user, cdcr_can_frame* frame) {
    Bus& b = *static_cast<Bus*>(user);
    if (b.inbox.empty()) return 0;
    *frame = b.inbox.front();
    b.inbox.erase(b.inbox.begin());
    return 1;
  };
  callbacks.can_set_filters = [](void* user, const cdcr_can_filter*, size_t count) {
    static_cast<Bus*>(user)->filters_set = int(count);
    return 1;
  };
}

// Two segments' CABLE_FEEDBACK frames of `lengths` into the bus's inbox, at
// first_id + segment.
void feed_cables(Bus& bus, const std::vector<float>& lengths, std::uint32_t first_id) {
  for (int s = 0; s < 2; ++s) {
    protocol::CableFeedback feedback;
    feedback.segment = s;
    for (int k = 0; k < 4; ++k) feedback.lengths_mm[k] = lengths[4 * s + k];
    hal::CanFrame frame;
    ASSERT_TRUE(protocol::encode(feedback, frame));
    cdcr_can_frame out{};
    out.id = first_id + std::uint32_t(s);
    out.dlc = frame.dlc;
    std::memcpy(out.data, frame.data, 8);
    bus.inbox.push_back(out);
  }
}

TEST_F(CApiRuntime, CanCallbacksCarryTheProtocol) {
  Bus bus;
  image = small_image();
  config = cdcr_config{};
  config.model_image = image.data();
  config.model_image_size = std::uint32_t(image.size());
  connect(config.callbacks, bus);
  ASSERT_EQ(cdcr_init(&runtime, &config), CDCR_OK);
  EXPECT_EQ(bus.filters_set, 3);  // cable feedback, targets, payload
  EXPECT_EQ(status().fault, CDCR_FAULT_NONE);

  // The same lengths as frames on the caller's bus give the same pose as fed.
  const std::vector<float> lengths = bent_cables(Geometry::uniform(2, 120.0f, 67.0f));
  feed_cables(bus, lengths, protocol::cable_feedback::kMessage.id);
  ASSERT_EQ(cdcr_step(&runtime), CDCR_OK);
  cdcr_pose from_bus{};
  ASSERT_EQ(cdcr_get_pose(&runtime, &from_bus), CDCR_OK);
  bool pose_sent = false;
  for (const cdcr_can_frame& frame : bus.sent) pose_sent = pose_sent || frame.id == protocol::pose_position_xy::kMessage.id;
  EXPECT_TRUE(pose_sent);

  step_with(lengths);
  cdcr_pose fed{};
  ASSERT_EQ(cdcr_get_pose(&runtime, &fed), CDCR_OK);
  EXPECT_EQ(std::memcmp(fed.position_mm, from_bus.position_mm, sizeof fed.position_mm), 0);

  // A receive without filters is the runtime's standing fault.
  config.callbacks.can_set_filters = nullptr;
  ASSERT_EQ(cdcr_init(&runtime, &config), CDCR_OK);
  EXPECT_EQ(status().fault, CDCR_FAULT_CAN_FILTERS_REFUSED);
}

// With the identifier base at 0x300 every frame moves 0x200 up, each way:
// cable feedback at 0x300 + s gives the pose, which goes out at 0x330; the
// same frames at the default identifiers are foreign.
TEST_F(CApiRuntime, AnIdentifierBaseMovesEveryFrame) {
  Bus bus;
  image = small_image();
  config = cdcr_config{};
  config.model_image = image.data();
  config.model_image_size = std::uint32_t(image.size());
  config.can_id_base = 0x304;  // not a multiple of 8
  connect(config.callbacks, bus);
  EXPECT_EQ(cdcr_init(&runtime, &config), CDCR_ERROR_INVALID_ARGUMENT);
  config.can_id_base = 0x788;  // the window would pass 0x7FF
  EXPECT_EQ(cdcr_init(&runtime, &config), CDCR_ERROR_INVALID_ARGUMENT);
  config.can_id_base = 0x300;
  ASSERT_EQ(cdcr_init(&runtime, &config), CDCR_OK);

  const std::vector<float> lengths = bent_cables(Geometry::uniform(2, 120.0f, 67.0f));
  feed_cables(bus, lengths, 0x100);  // the default identifiers: not the runtime's any more
  ASSERT_EQ(cdcr_step(&runtime), CDCR_OK);
  cdcr_pose pose{};
  EXPECT_NE(cdcr_get_pose(&runtime, &pose), CDCR_OK);
  feed_cables(bus, lengths, 0x300);
  bus.sent.clear();
  ASSERT_EQ(cdcr_step(&runtime), CDCR_OK);
  ASSERT_EQ(cdcr_get_pose(&runtime, &pose), CDCR_OK);
  bool pose_at_0x330 = false;
  for (const cdcr_can_frame& frame : bus.sent) {
    EXPECT_GE(frame.id, 0x300u);
    EXPECT_LT(frame.id, 0x380u);
    pose_at_0x330 = pose_at_0x330 || frame.id == 0x330;
  }
  EXPECT_TRUE(pose_at_0x330);
}

// Inputs given by call reach the runtime as their frames would: a runtime
// fed through cdcr_set_* and one fed the same inputs as frames on its bus
// send the same frames, byte for byte, with lengths, positions, quaternions
// and payload off the protocol's steps.
class CallsAndFrames {
 public:
  explicit CallsAndFrames(const std::vector<std::uint8_t>& image) {
    cdcr_config config{};
    config.model_image = image.data();
    config.model_image_size = std::uint32_t(image.size());
    config.fallback_geometry = cdcr_geometry{2, 120.0f, 67.0f, 1.5707963f, 0};
    for (int i = 0; i < 2; ++i) {
      connect(config.callbacks, buses_[i]);
      EXPECT_EQ(cdcr_init(&runtimes_[i], &config), CDCR_OK);
    }
  }

  void cables(const std::vector<float>& lengths) {
    ASSERT_EQ(cdcr_set_cable_lengths(&runtimes_[0], lengths.data(), lengths.size()), CDCR_OK);
    for (int s = 0; s < int(lengths.size()) / 4; ++s) {
      protocol::CableFeedback feedback;
      feedback.segment = s;
      for (int k = 0; k < 4; ++k) feedback.lengths_mm[k] = lengths[4 * s + k];
      hal::CanFrame frame;
      ASSERT_TRUE(protocol::encode(feedback, frame));
      put(frame);
    }
  }
  void target(const cdcr_target& target) {
    ASSERT_EQ(cdcr_set_target(&runtimes_[0], &target), CDCR_OK);
    hal::CanFrame frame;
    const bool pose = target.mode == CDCR_TARGET_POSE;
    if (pose) {
      protocol::encode(protocol::TargetOrientation{target.quaternion[0], target.quaternion[1], target.quaternion[2],
                                                   target.quaternion[3]},
                       frame);
      put(frame);
    }
    protocol::encode(protocol::TargetPositionXy{target.position_mm[0], target.position_mm[1]}, frame);
    put(frame);
    protocol::TargetPositionZ commit;
    commit.z_mm = target.position_mm[2];
    commit.mode = pose ? protocol::TargetMode::pose : protocol::TargetMode::position;
    commit.tracking = target.tracking != 0;
    commit.refuse_extrapolating = target.refuse_extrapolating != 0;
    commit.sequence = target.sequence;
    protocol::encode(commit, frame);
    put(frame);
  }
  void payload(float payload_kg) {
    ASSERT_EQ(cdcr_set_payload(&runtimes_[0], payload_kg), CDCR_OK);
    hal::CanFrame frame;
    ASSERT_TRUE(protocol::encode(protocol::Payload{payload_kg}, frame));
    put(frame);
  }
  // A step of both; what they computed is the same, to the bit.
  void step() {
    for (cdcr_runtime& runtime : runtimes_) ASSERT_EQ(cdcr_step(&runtime), CDCR_OK);
    cdcr_pose poses[2] = {};
    cdcr_setpoints setpoints[2] = {};
    cdcr_status statuses[2] = {};
    for (int i = 0; i < 2; ++i) {
      ASSERT_EQ(cdcr_get_pose(&runtimes_[i], &poses[i]), CDCR_OK);
      cdcr_get_setpoints(&runtimes_[i], &setpoints[i]);
      ASSERT_EQ(cdcr_get_status(&runtimes_[i], &statuses[i]), CDCR_OK);
    }
    EXPECT_EQ(std::memcmp(&poses[0], &poses[1], sizeof poses[0]), 0);
    EXPECT_EQ(std::memcmp(&setpoints[0], &setpoints[1], sizeof setpoints[0]), 0);
    EXPECT_EQ(std::memcmp(&statuses[0], &statuses[1], sizeof statuses[0]), 0);
  }
  const cdcr_runtime& by_calls() const { return runtimes_[0]; }
  const std::vector<cdcr_can_frame>& sent(int i) const { return buses_[i].sent; }

 private:
  void put(const hal::CanFrame& frame) {
    cdcr_can_frame out{};
    out.id = frame.id;
    out.dlc = frame.dlc;
    std::memcpy(out.data, frame.data, 8);
    buses_[1].inbox.push_back(out);
  }

  Bus buses_[2];
  cdcr_runtime runtimes_[2] = {};
};

TEST(CApiInputs, ByCallAndByFrameTheRuntimeSendsTheSameFrames) {
  CallsAndFrames runtimes(small_image(2, 0.0, /*payload_input=*/true));
  std::vector<float> lengths = bent_cables(Geometry::uniform(2, 120.0f, 67.0f), 0.1);
  // Between two of the protocol's steps, by a different fraction each.
  for (std::size_t i = 0; i < lengths.size(); ++i) lengths[i] += 0.0011f * float(i % 4 + 1);
  runtimes.cables(lengths);
  runtimes.step();
  cdcr_pose start{};
  ASSERT_EQ(cdcr_get_pose(&runtimes.by_calls(), &start), CDCR_OK);

  cdcr_target target{};
  target.position_mm[0] = start.position_mm[0] + 2.0037f;
  target.position_mm[1] = start.position_mm[1] - 1.0063f;
  target.position_mm[2] = start.position_mm[2] - 0.5041f;
  for (int i = 0; i < 4; ++i) target.quaternion[i] = start.quaternion[i];
  target.quaternion[1] += 0.00123f;  // off the Q15 steps, within the norm's tolerance
  target.mode = CDCR_TARGET_POSE;
  target.sequence = 7;
  runtimes.payload(0.2503f);
  runtimes.target(target);
  for (int k = 0; k < 40; ++k) {
    if (k == 20) {  // a streamed position target, and another one superseding it in the same step
      target.mode = CDCR_TARGET_POSITION;
      target.tracking = 1;
      target.position_mm[0] += 0.0313f;
      ++target.sequence;
      runtimes.target(target);
      target.position_mm[1] -= 0.0271f;
      ++target.sequence;
      runtimes.target(target);
    }
    runtimes.cables(lengths);
    runtimes.step();
  }
  const std::vector<cdcr_can_frame>& by_calls = runtimes.sent(0);
  const std::vector<cdcr_can_frame>& by_frames = runtimes.sent(1);
  int setpoints = 0;
  for (const cdcr_can_frame& frame : by_calls) setpoints += frame.id == protocol::cable_setpoint::kMessage.id;
  EXPECT_GT(setpoints, 0);
  ASSERT_EQ(by_calls.size(), by_frames.size());
  for (std::size_t i = 0; i < by_calls.size(); ++i) {
    EXPECT_EQ(by_calls[i].id, by_frames[i].id) << "frame " << i;
    EXPECT_EQ(by_calls[i].dlc, by_frames[i].dlc) << "frame " << i;
    EXPECT_EQ(std::memcmp(by_calls[i].data, by_frames[i].data, 8), 0) << "frame " << i << ", id " << by_calls[i].id;
  }
}

// A robot of three cables a segment: from its image (the cables block), or
// from the fallback geometry without one. Lengths go in three a segment and
// the setpoints come out so.
TEST_F(CApiRuntime, ThreeCablesASegment) {
  test_support::SyntheticModelOptions options;
  options.training_points = 8;
  options.cables_per_segment = 3;
  options.position_output_factor = 0.1;
  options.rotation_output_factor = 0.001;
  init(exporting::write_image(test_support::synthetic_trained_model(options)));
  EXPECT_EQ(status().state, CDCR_STATE_RUN);
  int cables = 0;
  ASSERT_EQ(cdcr_get_segment_cables(&runtime, 1, &cables), CDCR_OK);
  EXPECT_EQ(cables, 3);
  EXPECT_EQ(cdcr_get_segment_cables(&runtime, 2, &cables), CDCR_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(cdcr_get_segment_cables(&runtime, 0, nullptr), CDCR_ERROR_NULL_ARGUMENT);
  // Bent a little: eq. (2) for three anchors at 0, -120 and 120 degrees.
  const std::vector<float> lengths = {119.2f, 120.6f, 120.2f, 120.4f, 119.5f, 120.1f};
  const std::vector<float> four_a_segment(8, 120.0f);
  EXPECT_EQ(cdcr_set_cable_lengths(&runtime, four_a_segment.data(), four_a_segment.size()),
            CDCR_ERROR_INVALID_ARGUMENT);
  step_with(lengths, 3);
  cdcr_pose start{};
  ASSERT_EQ(cdcr_get_pose(&runtime, &start), CDCR_OK);
  EXPECT_EQ(start.compensated, 1);
  // One segment's three (the array holds no fourth).
  const float three[3] = {119.2f, 120.6f, 120.2f};
  EXPECT_EQ(cdcr_set_segment_cable_lengths(&runtime, 0, three), CDCR_OK);
  const cdcr_target target = position_target_near(start, 9);
  ASSERT_EQ(cdcr_set_target(&runtime, &target), CDCR_OK);
  step_while_solving(lengths);
  EXPECT_EQ(status().ik_outcome, CDCR_IK_CONVERGED);
  cdcr_setpoints setpoints{};
  ASSERT_EQ(cdcr_get_setpoints(&runtime, &setpoints), CDCR_OK);
  EXPECT_EQ(setpoints.cable_count, 6);
  for (int i = 0; i < 6; ++i) EXPECT_TRUE(std::isfinite(setpoints.lengths_mm[i]) && setpoints.lengths_mm[i] > 0.0f) << i;

  // Without an image, the fallback's three.
  config.model_image = nullptr;
  config.model_image_size = 0;
  config.fallback_geometry = cdcr_geometry{2, 120.0f, 67.0f, 1.5707963f, 3};
  ASSERT_EQ(cdcr_init(&runtime, &config), CDCR_OK);
  ASSERT_EQ(cdcr_get_segment_cables(&runtime, 0, &cables), CDCR_OK);
  EXPECT_EQ(cables, 3);
  step_with(lengths);
  cdcr_pose nominal{};
  ASSERT_EQ(cdcr_get_pose(&runtime, &nominal), CDCR_OK);
  EXPECT_EQ(nominal.compensated, 0);
  config.fallback_geometry = cdcr_geometry{2, 120.0f, 67.0f, 1.5707963f, 5};
  EXPECT_EQ(cdcr_init(&runtime, &config), CDCR_ERROR_INVALID_ARGUMENT);
}

TEST_F(CApiRuntime, EveryUnusableArgumentHasItsErrorCode) {
  cdcr_status s{};
  cdcr_pose pose{};
  cdcr_setpoints setpoints{};
  const float four[4] = {120, 120, 120, 120};
  // Storage no init has succeeded on.
  EXPECT_EQ(cdcr_step(&runtime), CDCR_ERROR_NOT_INITIALIZED);
  EXPECT_EQ(cdcr_get_status(&runtime, &s), CDCR_ERROR_NOT_INITIALIZED);
  EXPECT_EQ(cdcr_set_segment_cable_lengths(&runtime, 0, four), CDCR_ERROR_NOT_INITIALIZED);
  EXPECT_EQ(cdcr_step(nullptr), CDCR_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(cdcr_init(nullptr, &config), CDCR_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(cdcr_init(&runtime, nullptr), CDCR_ERROR_NULL_ARGUMENT);
  config.model_image_size = 100;  // a size without an image
  EXPECT_EQ(cdcr_init(&runtime, &config), CDCR_ERROR_NULL_ARGUMENT);
  config.model_image_size = 0;
  config.fallback_geometry = cdcr_geometry{9, 120.0f, 67.0f, 1.5f, 0};
  EXPECT_EQ(cdcr_init(&runtime, &config), CDCR_ERROR_INVALID_ARGUMENT);
  config.fallback_geometry = cdcr_geometry{2, 120.0f, -67.0f, 1.5f, 0};
  EXPECT_EQ(cdcr_init(&runtime, &config), CDCR_ERROR_INVALID_ARGUMENT);
  config.fallback_geometry = cdcr_geometry{};
  config.period_ns = -1;
  EXPECT_EQ(cdcr_init(&runtime, &config), CDCR_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(cdcr_step(&runtime), CDCR_ERROR_NOT_INITIALIZED);

  init({});  // two segments, no image
  EXPECT_EQ(cdcr_get_pose(&runtime, &pose), CDCR_ERROR_NO_DATA);
  EXPECT_EQ(cdcr_get_setpoints(&runtime, &setpoints), CDCR_ERROR_NO_DATA);
  EXPECT_EQ(cdcr_get_pose(&runtime, nullptr), CDCR_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(cdcr_get_setpoints(&runtime, nullptr), CDCR_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(cdcr_get_status(&runtime, nullptr), CDCR_ERROR_NULL_ARGUMENT);

  // Cable lengths.
  const float eight[8] = {120, 120, 120, 120, 120, 120, 120, 120};
  EXPECT_EQ(cdcr_set_cable_lengths(&runtime, nullptr, 8), CDCR_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(cdcr_set_cable_lengths(&runtime, eight, 4), CDCR_ERROR_INVALID_ARGUMENT);  // 2 segments: 8
  EXPECT_EQ(cdcr_set_cable_lengths(&runtime, eight, 16), CDCR_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(cdcr_set_segment_cable_lengths(&runtime, 2, four), CDCR_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(cdcr_set_segment_cable_lengths(&runtime, -1, four), CDCR_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(cdcr_set_segment_cable_lengths(&runtime, 0, nullptr), CDCR_ERROR_NULL_ARGUMENT);
  for (const float bad : {std::nanf(""), INFINITY, 0.0f, -5.0f, 655.35f, 700.0f}) {
    float lengths[8] = {120, 120, 120, 120, 120, 120, 120, 120};
    lengths[5] = bad;
    EXPECT_EQ(cdcr_set_cable_lengths(&runtime, lengths, 8), CDCR_ERROR_OUT_OF_RANGE) << bad;
  }
  // Nothing of a refused set reached the runtime.
  ASSERT_EQ(cdcr_step(&runtime), CDCR_OK);
  EXPECT_EQ(cdcr_get_pose(&runtime, &pose), CDCR_ERROR_NO_DATA);
  EXPECT_EQ(status().rejected_frames, 0u);

  // Targets.
  cdcr_target target{};
  target.position_mm[2] = 230.0f;
  target.quaternion[0] = 1.0f;
  target.mode = CDCR_TARGET_POSE;
  EXPECT_EQ(cdcr_set_target(&runtime, nullptr), CDCR_ERROR_NULL_ARGUMENT);
  target.quaternion[0] = 0.9f;  // not of unit norm
  EXPECT_EQ(cdcr_set_target(&runtime, &target), CDCR_ERROR_INVALID_ARGUMENT);
  target.quaternion[0] = 2.0f;  // would saturate to a unit quaternion in Q15
  EXPECT_EQ(cdcr_set_target(&runtime, &target), CDCR_ERROR_INVALID_ARGUMENT);
  target.quaternion[0] = std::nanf("");
  EXPECT_EQ(cdcr_set_target(&runtime, &target), CDCR_ERROR_OUT_OF_RANGE);
  target.quaternion[0] = 1.0f;
  target.position_mm[0] = INFINITY;
  EXPECT_EQ(cdcr_set_target(&runtime, &target), CDCR_ERROR_OUT_OF_RANGE);
  target.position_mm[0] = 3e7f;
  EXPECT_EQ(cdcr_set_target(&runtime, &target), CDCR_ERROR_OUT_OF_RANGE);
  target.position_mm[0] = 0.0f;
  target.mode = static_cast<cdcr_target_mode>(5);
  EXPECT_EQ(cdcr_set_target(&runtime, &target), CDCR_ERROR_INVALID_ARGUMENT);
  target.mode = CDCR_TARGET_POSITION;
  target.quaternion[0] = 0.0f;  // not used for a position target
  EXPECT_EQ(cdcr_set_target(&runtime, &target), CDCR_OK);

  // The queue between two steps holds what a cycle carries, and says when full.
  cdcr_result last = CDCR_OK;
  int accepted = 0;
  for (int k = 0; k < 100 && last == CDCR_OK; ++k) {
    last = cdcr_set_segment_cable_lengths(&runtime, 0, four);
    accepted += last == CDCR_OK;
  }
  EXPECT_EQ(last, CDCR_ERROR_QUEUE_FULL);
  EXPECT_GE(accepted, 2 * CDCR_MAX_SEGMENTS);
  EXPECT_EQ(cdcr_step(&runtime), CDCR_OK);
  EXPECT_EQ(cdcr_set_cable_lengths(&runtime, eight, 8), CDCR_OK);

  EXPECT_STREQ(cdcr_result_name(CDCR_ERROR_QUEUE_FULL), "queue full");
  EXPECT_STREQ(cdcr_state_name(CDCR_STATE_DEGRADED), "DEGRADED");
  EXPECT_STREQ(cdcr_fault_name(CDCR_FAULT_IMAGE_MISSING), "model image missing");
}

TEST(CApi, StorageHoldsTheRuntime) {
  EXPECT_GT(cdcr_runtime_storage_size(), sizeof(Runtime));
  EXPECT_LE(cdcr_runtime_storage_size(), std::size_t(CDCR_RUNTIME_STORAGE_BYTES));
  EXPECT_EQ(sizeof(cdcr_runtime), std::size_t(CDCR_RUNTIME_STORAGE_BYTES));
}

}  // namespace
}  // namespace cdcr::firmware
