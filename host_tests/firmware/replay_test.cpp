// cdcr-runtime --replay runs the firmware's forward path; over the same image
// and cables its poses agree with `cdcr eval`'s firmware poses
// (training::firmware_poses), and its radii and extrapolation flags with
// eval's (training::firmware_estimates).

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "dataset/csv_dataset.hpp"
#include "runtime_fixture.hpp"
#include "train/evaluation.hpp"
#include "train/predictive_variance.hpp"

#include "../support/random_joints.hpp"

namespace cdcr::firmware {
namespace {

// The variance factor holds one kernel for every output, as the trainer's;
// fitted on `points` of the model's inputs.
void fit_variance(training::TrainedModel& trained, int points) {
  trained.signal_variance.setConstant(trained.signal_variance[0]);
  trained.noise_variance.setConstant(trained.noise_variance[0]);
  trained.variance = training::fit_variance_factor(trained, trained.inputs,
                                                   training::variance_points(trained, trained.inputs, points, 1));
  trained.variance.extrapolation_variance = 0.5;
}

// `samples` rows of cables from joints drawn in alpha [-pi, pi] and theta
// [0, 1.2] rad through `geometry`; with_payload: a payload in [0, 1] kg
// after each row's cables.
void random_cables(const model::RobotGeometry<double>& geometry, int samples, unsigned seed, bool with_payload,
                   dataset::Dataset& data) {
  data.segment_count = geometry.segment_count;
  data.cables_mm.resize(samples, 4 * geometry.segment_count);
  data.has_payload = with_payload;
  if (with_payload) data.payload_kg.resize(samples);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> alpha(-M_PI, M_PI), theta(0.0, 1.2), payload(0.0, 1.0);
  for (int i = 0; i < samples; ++i) {
    const model::JointVector<double> joints = test_support::random_joints(geometry.segment_count, rng, alpha, theta);
    model::CableVector<double> cables;
    ASSERT_EQ(model::cables_from_joints(joints, geometry, cables), model::Status::ok);
    data.cables_mm.row(i) = cables.transpose();
    if (with_payload) data.payload_kg[i] = payload(rng);
  }
}

void write_bytes(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The image and the cables, as the replay reads them, in `dir`: model.img
// and cables.csv.
void write_replay_inputs(const std::filesystem::path& dir, const std::vector<std::uint8_t>& image,
                         const dataset::Dataset& data) {
  std::filesystem::create_directories(dir);
  write_bytes(dir / "model.img", image);
  dataset::write_dataset_csv((dir / "cables.csv").string(), data);
}

int run_replay(const std::filesystem::path& dir, const std::string& image, const std::string& cables,
               const std::string& extra = "") {
  const std::string command = std::string("\"") + CDCR_RUNTIME_EXE + "\" --image \"" + (dir / image).string() +
                              "\" --replay \"" + (dir / cables).string() + "\" --out \"" +
                              (dir / "poses.csv").string() + "\"" + extra;
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// run_replay with its standard error in `errors`.
int run_replay_capturing_errors(const std::filesystem::path& dir, const std::string& image, const std::string& cables,
                                std::string& errors) {
  const std::filesystem::path err = dir / "err.txt";
  const int exit_code = run_replay(dir, image, cables, " 2>\"" + err.string() + "\"");
  errors = read_text(err);
  return exit_code;
}

void expect_one_line_naming(const std::string& message, const std::string& cause) {
  EXPECT_NE(message.find(cause), std::string::npos) << message;
  EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << message;
}

TEST(RuntimeReplay, MatchesTheEvaluationsFirmwarePoses) {
  training::TrainedModel trained = test_support::synthetic_trained_model();
  fit_variance(trained, std::min(16, trained.training_points()));
  const std::vector<std::uint8_t> image = exporting::write_image(trained);
  model::ImageView view;
  ASSERT_EQ(model::parse_image(image.data(), image.size(), view), model::ImageStatus::ok);
  model::RobotGeometry<double> geometry;
  ASSERT_EQ(model::geometry_from_image(view, geometry), model::Status::ok);

  dataset::Dataset data;
  ASSERT_NO_FATAL_FAILURE(random_cables(geometry, 200, 3, false, data));

  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "cdcr_runtime_replay";
  write_replay_inputs(dir, image, data);
  ASSERT_EQ(run_replay(dir, "model.img", "cables.csv"), 0);

  // The replay reads the cables back from the CSV, as cdcr eval does.
  const dataset::Dataset written = dataset::read_dataset_csv((dir / "cables.csv").string());
  const std::vector<model::Pose<double>> reference = training::firmware_poses(view, written.cables_mm);

  const std::vector<training::FirmwareEstimate> estimates = training::firmware_estimates(view, written.cables_mm);

  std::ifstream in(dir / "poses.csv");
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "x,y,z,qw,qx,qy,qz,r95_mm,r95_deg,extrapolating");
  std::vector<model::Pose<double>> replayed;
  int extrapolating = 0;
  while (std::getline(in, line)) {
    double v[9];
    int flag = -1;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%d", &v[0], &v[1], &v[2], &v[3], &v[4],
                          &v[5], &v[6], &v[7], &v[8], &flag),
              10);
    model::Pose<double> pose;
    pose.position_mm = model::Vec3<double>(v[0], v[1], v[2]);
    pose.rotation = Eigen::Quaterniond(v[3], v[4], v[5], v[6]).normalized().toRotationMatrix();
    const std::size_t row = replayed.size();
    ASSERT_LT(row, estimates.size());
    // The same float code on the same inputs: printed to 9 digits, the same.
    EXPECT_FLOAT_EQ(static_cast<float>(v[7]), static_cast<float>(estimates[row].uncertainty.r95_mm)) << row;
    EXPECT_FLOAT_EQ(static_cast<float>(v[8]), static_cast<float>(estimates[row].uncertainty.r95_deg)) << row;
    EXPECT_GT(v[7], 0.0);
    EXPECT_EQ(flag, estimates[row].uncertainty.extrapolating ? 1 : 0) << row;
    extrapolating += flag;
    replayed.push_back(pose);
  }
  ASSERT_EQ(replayed.size(), reference.size());
  const training::Fidelity fidelity = training::compare_poses(reference, replayed);
  EXPECT_LT(fidelity.max_position_mm, 0.01);
  EXPECT_LT(fidelity.max_orientation_deg, 0.001);
  // Joint angles up to 1.2 rad against a model fitted on a small region:
  // some rows extrapolate, not all.
  EXPECT_GT(extrapolating, 0);
  EXPECT_LT(extrapolating, static_cast<int>(replayed.size()));
}

// The line --replay writes for an estimate, formatted here as the tool
// formats it.
std::string replay_line(const training::FirmwareEstimate& e) {
  Eigen::Quaterniond q(e.pose.rotation);
  q.normalize();
  if (q.w() < 0) q.coeffs() *= -1.0;
  char line[256];
  std::snprintf(line, sizeof line, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d", e.pose.position_mm.x(),
                e.pose.position_mm.y(), e.pose.position_mm.z(), q.w(), q.x(), q.y(), q.z(), e.uncertainty.r95_mm,
                e.uncertainty.r95_deg, e.uncertainty.extrapolating ? 1 : 0);
  return line;
}

// With a payload model and the payload beside the cables in each row, the
// replay's output is eval's float32 path (training::firmware_estimates with
// the rows' payloads), line for line and digit for digit; the payload moves
// the poses (the rows differ from the same cables at the default payload).
TEST(RuntimeReplay, WithThePayloadInEachRowEqualsTheEvaluationBitForBit) {
  test_support::SyntheticModelOptions options;
  options.training_points = 40;
  options.payload_input = true;
  training::TrainedModel trained = test_support::synthetic_trained_model(options);
  fit_variance(trained, 12);
  const std::vector<std::uint8_t> image = exporting::write_image(trained);
  model::ImageView view;
  ASSERT_EQ(model::parse_image(image.data(), image.size(), view), model::ImageStatus::ok);
  ASSERT_EQ(view.extra_inputs, 1);
  model::RobotGeometry<double> geometry;
  ASSERT_EQ(model::geometry_from_image(view, geometry), model::Status::ok);

  const int samples = 120;
  dataset::Dataset data;
  ASSERT_NO_FATAL_FAILURE(random_cables(geometry, samples, 4, true, data));
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "cdcr_runtime_replay_payload";
  write_replay_inputs(dir, image, data);
  ASSERT_EQ(run_replay(dir, "model.img", "cables.csv"), 0);

  const dataset::Dataset written = dataset::read_dataset_csv((dir / "cables.csv").string());
  ASSERT_TRUE(written.has_payload);
  const std::vector<training::FirmwareEstimate> estimates =
      training::firmware_estimates(view, written.cables_mm, written.payload_kg);
  // eval's poses are these estimates' poses: the same float32 path.
  const std::vector<model::Pose<double>> poses =
      training::firmware_poses(view, written.cables_mm, training::FirmwareAccumulator::float64, written.payload_kg);
  const std::vector<training::FirmwareEstimate> at_default =
      training::firmware_estimates(view, written.cables_mm, Eigen::VectorXd::Constant(samples, 0.375));
  std::ifstream in(dir / "poses.csv");
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  std::size_t row = 0;
  int moved = 0;
  while (std::getline(in, line)) {
    ASSERT_LT(row, estimates.size());
    EXPECT_EQ(line, replay_line(estimates[row])) << "row " << row;
    EXPECT_EQ(poses[row].position_mm, estimates[row].pose.position_mm) << "row " << row;
    if (line != replay_line(at_default[row])) ++moved;
    ++row;
  }
  EXPECT_EQ(row, estimates.size());
  EXPECT_GT(moved, 0.9 * samples);
}

// A payload image over cables without the column is refused in one line; a
// model without the input replays a file with the column and says it
// ignores it.
TEST(RuntimeReplay, ThePayloadColumnMustMatchTheImage) {
  test_support::SyntheticModelOptions options;
  options.payload_input = true;
  const std::vector<std::uint8_t> payload_image = exporting::write_image(test_support::synthetic_trained_model(options));
  const std::vector<std::uint8_t> plain_image = exporting::write_image(test_support::synthetic_trained_model());
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "cdcr_runtime_replay_column";
  std::filesystem::create_directories(dir);
  write_bytes(dir / "payload.img", payload_image);
  write_bytes(dir / "plain.img", plain_image);
  { std::ofstream(dir / "plain.csv") << "l1_1,l1_2,l1_3,l1_4,l2_1,l2_2,l2_3,l2_4\n120,120,120,120,95.5,95.5,95.5,95.5\n"; }
  {
    std::ofstream(dir / "loaded.csv")
        << "l1_1,l1_2,l1_3,l1_4,l2_1,l2_2,l2_3,l2_4,payload_kg\n120,120,120,120,95.5,95.5,95.5,95.5,0.5\n";
  }
  std::string message;
  EXPECT_EQ(run_replay_capturing_errors(dir, "payload.img", "plain.csv", message), 1);
  expect_one_line_naming(message, "the image takes a payload input and the data have no payload_kg column");

  std::string note;
  EXPECT_EQ(run_replay_capturing_errors(dir, "plain.img", "loaded.csv", note), 0);
  EXPECT_NE(note.find("the payload_kg column is ignored"), std::string::npos) << note;
  EXPECT_EQ(run_replay(dir, "payload.img", "loaded.csv"), 0);
}

// A motion sequence of two sessions with a hysteresis image: the replay
// carries the state from row to row, each session from home, and its poses
// are the runtime's on the effective lengths of a float32 run of the
// operator written out here; with the history inputs, given where each
// cable last moved, read from the same run.
void expect_replay_carries_the_state(bool history, const char* folder) {
  test_support::SyntheticModelOptions options;
  options.hysteresis_operators = 2;
  options.history = history;
  const training::TrainedModel trained = test_support::synthetic_trained_model(options);
  const std::vector<std::uint8_t> image = exporting::write_image(trained);
  test_support::SimulatedPlatform platform(image);
  Runtime runtime(platform.hal, Geometry::prototype());
  ASSERT_EQ(runtime.init(), RuntimeState::run);
  const model::HysteresisModel<float>& h = runtime.hysteresis().hysteresis_model();
  ASSERT_EQ(h.cables, 8);

  // 60 rows: a random walk of the bend, two sessions (a gap of a minute).
  dataset::Dataset data;
  data.segment_count = 2;
  data.has_time = true;
  data.cables_mm.resize(60, 8);
  data.time_s.resize(60);
  model::RobotGeometry<double> geometry = trained.geometry;
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> step(-0.03, 0.03);
  model::JointVector<double> joints(4);
  joints << 0.4, 0.1, -1.0, 0.12;
  for (int i = 0; i < 60; ++i) {
    model::CableVector<double> cables;
    ASSERT_EQ(test_support::random_walk_step(joints, rng, step, geometry, cables), model::Status::ok);
    data.cables_mm.row(i) = cables.transpose();
    data.time_s[i] = 0.1 * i + (i >= 35 ? 60.0 : 0.0);
  }
  data.session_starts = {0, 35};
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / folder;
  write_replay_inputs(dir, image, data);
  ASSERT_EQ(run_replay(dir, "model.img", "cables.csv"), 0);
  const dataset::Dataset written = dataset::read_dataset_csv((dir / "cables.csv").string());
  ASSERT_TRUE(written.has_time);
  ASSERT_EQ(written.session_starts, data.session_starts);

  std::ifstream in(dir / "poses.csv");
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  model::HysteresisState<float> state;
  double largest_effect_mm = 0.0;
  for (int i = 0; i < 60; ++i) {
    ASSERT_TRUE(std::getline(in, line)) << i;
    double x = 0, y = 0, z = 0;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf", &x, &y, &z), 3);
    if (i == 0 || i == 35) {
      ASSERT_EQ(model::start_at_home(state, h, runtime.geometry()), model::Status::ok);
    }
    const Cables commanded = written.cables_mm.row(i).transpose().cast<float>();
    model::update_hysteresis(state, h, commanded);
    Cables effective;
    model::effective_lengths(state, h, effective);
    float row_history[8];
    model::history_inputs(state, h, row_history);
    runtime.set_history_inputs(row_history);
    PoseEstimate expected, joints_only;
    ASSERT_EQ(runtime.estimate_pose(effective, expected), model::Status::ok);
    ASSERT_EQ(runtime.estimate_pose(commanded, joints_only), model::Status::ok);
    EXPECT_EQ(float(x), expected.pose.position_mm.x()) << i;
    EXPECT_EQ(float(y), expected.pose.position_mm.y()) << i;
    EXPECT_EQ(float(z), expected.pose.position_mm.z()) << i;
    largest_effect_mm =
        std::max(largest_effect_mm, double((expected.pose.position_mm - joints_only.pose.position_mm).norm()));
  }
  EXPECT_GT(largest_effect_mm, 0.1) << "the hysteresis must matter on these rows";
}

TEST(RuntimeReplay, AHysteresisImageCarriesTheStateOverTheSequence) {
  expect_replay_carries_the_state(false, "cdcr_runtime_replay_sequence");
}

TEST(RuntimeReplay, AHistoryImageTakesWhereEachCableLastMovedOnEveryRow) {
  expect_replay_carries_the_state(true, "cdcr_runtime_replay_history");
}

// An image that models the cables' hysteresis needs the rows as a motion
// sequence (a t_s column): rows without time are refused in one line.
TEST(RuntimeReplay, AHysteresisImageNeedsAMotionSequence) {
  test_support::SyntheticModelOptions options;
  options.hysteresis_operators = 2;
  const std::vector<std::uint8_t> image = exporting::write_image(test_support::synthetic_trained_model(options));
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "cdcr_runtime_replay_hysteresis";
  std::filesystem::create_directories(dir);
  write_bytes(dir / "hysteresis.img", image);
  { std::ofstream(dir / "plain.csv") << "l1_1,l1_2,l1_3,l1_4,l2_1,l2_2,l2_3,l2_4\n120,120,120,120,95.5,95.5,95.5,95.5\n"; }
  std::string message;
  EXPECT_EQ(run_replay_capturing_errors(dir, "hysteresis.img", "plain.csv", message), 1);
  expect_one_line_naming(message, "needs a motion sequence (a t_s column), but the rows have no time");
}

TEST(RuntimeReplay, CorruptImageIsOneLineErrorWithExitOne) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "cdcr_runtime_replay_bad";
  std::filesystem::create_directories(dir);
  { std::ofstream(dir / "bad.img") << "not an image"; }
  { std::ofstream(dir / "c.csv") << "l1_1,l1_2,l1_3,l1_4\n120,120,120,120\n"; }
  const std::string command = std::string("\"") + CDCR_RUNTIME_EXE + "\" --image \"" + (dir / "bad.img").string() +
                              "\" --replay \"" + (dir / "c.csv").string() + "\" --out \"" +
                              (dir / "p.csv").string() + "\" 2>/dev/null";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
  const int usage = std::system((std::string("\"") + CDCR_RUNTIME_EXE + "\" --replay x 2>/dev/null").c_str());
  ASSERT_TRUE(WIFEXITED(usage));
  EXPECT_EQ(WEXITSTATUS(usage), 2);
}

// The closed loop following a streamed circle (`--sim --circle`) on the
// ideal robot, with a model whose corrections are about a millimetre: a pose
// in every cycle, no overrun, setpoints in every streamed cycle that solve
// each cycle's target on the runtime's own compensated model, and the
// robot's tip within those corrections of the targets.
TEST(RuntimeClosedLoop, FollowsAStreamedCircle) {
  test_support::SyntheticModelOptions options;
  options.training_points = 200;
  options.segments = 4;
  training::TrainedModel m = test_support::synthetic_trained_model(options);
  for (int k = 0; k < 6; ++k) {
    m.output_mean[k] *= k < 3 ? 0.1 : 0.001;
    m.output_scale[k] *= k < 3 ? 0.1 : 0.001;
  }
  const std::vector<std::uint8_t> image = exporting::write_image(m);
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "cdcr_runtime_circle";
  std::filesystem::create_directories(dir);
  write_bytes(dir / "model.img", image);
  const std::string command = std::string("\"") + CDCR_RUNTIME_EXE + "\" --image \"" + (dir / "model.img").string() +
                              "\" --sim --ideal-robot --circle --circle-radius 30 --circle-speed 100 > \"" +
                              (dir / "out.txt").string() + "\"";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  const std::string text = read_text(dir / "out.txt");
  double tip_mean = -1, tip_max = -1, following_mean = -1, following_max = -1;
  long sent = -1, streamed = -1, without = -1, cycles = -1, missing = -1;
  unsigned overruns = 1;
  const std::size_t tip_at = text.find("tip vs streamed target");
  ASSERT_NE(tip_at, std::string::npos) << text;
  ASSERT_EQ(std::sscanf(text.c_str() + text.find(": mean", tip_at), ": mean %lf mm, max %lf mm", &tip_mean, &tip_max), 2)
      << text;
  const std::size_t at = text.find("of which following");
  ASSERT_NE(at, std::string::npos) << text;
  ASSERT_EQ(std::sscanf(text.c_str() + text.find(": mean", at), ": mean %lf mm, max %lf mm", &following_mean,
                        &following_max),
            2)
      << text;
  const std::size_t sent_at = text.find("setpoints sent in");
  ASSERT_NE(sent_at, std::string::npos) << text;
  ASSERT_EQ(std::sscanf(text.c_str() + sent_at,
                        "setpoints sent in %ld of %ld streamed cycles (none in %ld after the first 3); cycles %ld, "
                        "poses missing %ld, overruns %u",
                        &sent, &streamed, &without, &cycles, &missing, &overruns),
            6)
      << text;
  EXPECT_GT(streamed, 1000);
  EXPECT_EQ(sent, streamed);
  EXPECT_EQ(without, 0);
  EXPECT_EQ(missing, 0);
  EXPECT_EQ(overruns, 0u);
  EXPECT_LT(following_mean, 0.05) << text;
  EXPECT_LT(following_max, 0.2) << text;
  // The corrections are the only difference between the model and the robot.
  EXPECT_LT(tip_mean, 2.0) << text;
}

}  // namespace
}  // namespace cdcr::firmware
