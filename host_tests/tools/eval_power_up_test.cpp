// cdcr eval --from-power-up: the first session of a motion sequence starts
// with the hysteresis state unknown, as the board powers up, and the r95
// radii are widened as the runtime widens them until the state is known.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cdcr/model/compensated_kinematics.hpp"
#include "cdcr/model/flash_image.hpp"
#include "cdcr/model/gp_correction.hpp"
#include "dataset/csv_dataset.hpp"
#include "export/binary_file.hpp"
#include "export/image_writer.hpp"
#include "test_work_dir.hpp"
#include "train/predictive_variance.hpp"
#include "../support/variance_block.hpp"

#include "../support/run_cdcr.hpp"
#include "../support/synthetic_trained_model.hpp"

namespace cdcr::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string quoted(const fs::path& path) { return "'" + path.string() + "'"; }

bool one_line(const std::string& text) {
  return !text.empty() && text.back() == '\n' && text.find('\n') == text.size() - 1;
}

// The r95_mm and r95_deg columns of `cdcr eval --rows`.
struct RowRadii {
  std::vector<double> mm, deg;
};
RowRadii read_radii(const fs::path& path) {
  std::ifstream file(path);
  std::string line;
  std::getline(file, line);
  int mm_column = -1, deg_column = -1, column = 0;
  std::stringstream header(line);
  for (std::string name; std::getline(header, name, ','); ++column) {
    if (name == "r95_mm") mm_column = column;
    if (name == "r95_deg") deg_column = column;
  }
  RowRadii radii;
  while (std::getline(file, line)) {
    std::stringstream fields(line);
    column = 0;
    for (std::string field; std::getline(fields, field, ','); ++column) {
      if (column == mm_column) radii.mm.push_back(std::stod(field));
      if (column == deg_column) radii.deg.push_back(std::stod(field));
    }
  }
  return radii;
}

class EvalPowerUp : public ::testing::Test {
 protected:
  void SetUp() override { dir = test_support::fresh_test_work_dir(); }

  static test_support::CliRun cdcr(const std::string& arguments) { return test_support::run_cdcr(arguments); }

  // A model of 2 segments with a hysteresis block (two operators per cable)
  // and a variance block.
  static training::TrainedModel model_with_variance() {
    test_support::SyntheticModelOptions options;
    options.training_points = 40;
    options.hysteresis_operators = 2;
    options.position_output_factor = 0.1;
    options.rotation_output_factor = 0.001;
    training::TrainedModel m = test_support::synthetic_trained_model(options);
    test_support::add_variance_block(m, 8);
    return m;
  }

  // A motion sequence of `rows` rows, in two sessions if longer than 60 (the
  // second from row 60): the bend drifts and wanders, so every cable soon travels more than
  // twice its widest operator in one direction. Poses: the commanded
  // lengths' compensated ones (only the radii are compared).
  fs::path write_sequence(const training::TrainedModel& m, int rows) const {
    const std::vector<std::uint8_t> image = exporting::write_image(m);
    model::ImageView view{};
    EXPECT_EQ(model::parse_image(image.data(), image.size(), view), model::ImageStatus::ok);
    model::RobotGeometry<double> geometry;
    EXPECT_EQ(model::geometry_from_image(view, geometry), model::Status::ok);
    model::GpCorrection<double, double> correction;
    EXPECT_EQ(correction.bind(view), model::Status::ok);
    dataset::Dataset data;
    data.segment_count = 2;
    data.has_time = true;
    data.has_poses = true;
    data.cables_mm.resize(rows, 8);
    data.time_s.resize(rows);
    data.session_starts = rows > 60 ? std::vector<int>{0, 60} : std::vector<int>{0};
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> step(-0.15, 0.15);
    model::JointVector<double> joints(4);
    joints << 0.3, 0.4, 2.0, 0.3;
    for (int i = 0; i < rows; ++i) {
      for (int k = 0; k < 4; k += 2) joints[k] += 0.4 + step(rng);
      for (int k = 1; k < 4; k += 2) joints[k] = std::clamp(std::abs(joints[k] + step(rng)), 0.05, 1.0);
      model::CableVector<double> cables;
      EXPECT_EQ(model::cables_from_joints(joints, geometry, cables), model::Status::ok);
      data.cables_mm.row(i) = cables.transpose();
      data.time_s[i] = 0.5 * i + (i >= 60 ? 100.0 : 0.0);
      model::ForwardResult<double> pose;
      EXPECT_EQ(model::compensated_forward(cables, geometry, correction, pose), model::Status::ok);
      data.poses.push_back(pose.compensated);
    }
    const fs::path path = dir / "sequence.csv";
    dataset::write_dataset_csv(path.string(), data);
    return path;
  }

  fs::path save_image(const std::string& name, const training::TrainedModel& m) const {
    const std::vector<std::uint8_t> bytes = exporting::write_image(m);
    const fs::path path = dir / name;
    exporting::write_binary_file(path.string(), bytes.data(), bytes.size());
    return path;
  }

  fs::path dir;
};

// The same rows evaluated from home and from power-up: wider radii while the
// state is unknown (the first rows), the same radii once it is known, and
// the second session (from home) untouched.
TEST_F(EvalPowerUp, UnknownStateWidensTheFirstRowsOnly) {
  const training::TrainedModel m = model_with_variance();
  const fs::path image = save_image("model.img", m);
  const fs::path data = write_sequence(m, 90);
  const fs::path home_rows = dir / "home.csv", power_up_rows = dir / "power_up.csv";
  const test_support::CliRun home =
      cdcr("eval --json --model " + quoted(image) + " --data " + quoted(data) + " --rows " + quoted(home_rows));
  ASSERT_EQ(home.exit_code, 0) << home.err;
  const test_support::CliRun power_up = cdcr("eval --json --from-power-up --first-rows 5 --model " + quoted(image) +
                                             " --data " + quoted(data) + " --rows " + quoted(power_up_rows));
  ASSERT_EQ(power_up.exit_code, 0) << power_up.err;
  const json j = json::parse(power_up.out);
  const int unknown_rows = j["power_up"]["unknown_rows"].get<int>();
  ASSERT_GE(unknown_rows, 2) << power_up.out;
  ASSERT_LT(unknown_rows, 30) << "the path must make the state known well within the first session";
  EXPECT_EQ(j["power_up"]["first_rows"]["rows"], 5) << power_up.out;
  EXPECT_EQ(j["power_up"]["later_rows"]["rows"], 85) << power_up.out;

  const RowRadii from_home = read_radii(home_rows), from_power_up = read_radii(power_up_rows);
  ASSERT_EQ(from_home.mm.size(), 90u);
  ASSERT_EQ(from_power_up.mm.size(), 90u);
  for (int i = 0; i < unknown_rows; ++i) {
    EXPECT_GT(from_power_up.mm[i], 1.2 * from_home.mm[i]) << "row " << i;
    EXPECT_GT(from_power_up.deg[i], 1.2 * from_home.deg[i]) << "row " << i;
  }
  // Once known, the lags are those the path leaves whatever they were: the
  // same as from home, to float32 rounding of the two paths.
  for (int i = unknown_rows; i < 90; ++i) {
    EXPECT_NEAR(from_power_up.mm[i], from_home.mm[i], 1e-4 * from_home.mm[i]) << "row " << i;
    EXPECT_NEAR(from_power_up.deg[i], from_home.deg[i], 1e-4 * from_home.deg[i]) << "row " << i;
  }

  const test_support::CliRun text =
      cdcr("eval --from-power-up --model " + quoted(image) + " --data " + quoted(data));
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("the first from power-up (state unknown for its first " + std::to_string(unknown_rows) +
                          " rows, r95 widened)"),
            std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("within r95, first  20 rows"), std::string::npos) << text.out;
}

// Rows without time are independent samples: there is no power-up to start
// from. An image without a hysteresis block has no state to be unknown.
TEST_F(EvalPowerUp, NeedsAMotionSequenceAndAHysteresisImage) {
  const fs::path samples = dir / "samples.csv";
  ASSERT_EQ(cdcr("simulate --samples 12 --seed 4 --segments 2 --out " + quoted(samples)).exit_code, 0);
  training::TrainedModel plain = model_with_variance();
  plain.hysteresis = model::HysteresisModel<double>{};
  const test_support::CliRun no_time =
      cdcr("eval --from-power-up --model " + quoted(save_image("plain.img", plain)) + " --data " + quoted(samples));
  EXPECT_EQ(no_time.exit_code, 1);
  EXPECT_TRUE(one_line(no_time.err)) << no_time.err;
  EXPECT_NE(no_time.err.find("--from-power-up needs a motion sequence (a t_s column), but the rows have no time"),
            std::string::npos)
      << no_time.err;
  // Without the option the same files evaluate.
  EXPECT_EQ(cdcr("eval --model " + quoted(dir / "plain.img") + " --data " + quoted(samples)).exit_code, 0);

  const fs::path sequence = write_sequence(model_with_variance(), 20);
  const test_support::CliRun no_block =
      cdcr("eval --from-power-up --model " + quoted(dir / "plain.img") + " --data " + quoted(sequence));
  EXPECT_EQ(no_block.exit_code, 1);
  EXPECT_TRUE(one_line(no_block.err)) << no_block.err;
  EXPECT_NE(no_block.err.find("--from-power-up needs an image with a hysteresis block"), std::string::npos)
      << no_block.err;
}

}  // namespace
}  // namespace cdcr::cli
