// cdcr simulate --hysteresis: the session written as a motion sequence (a t_s
// column), its refusals, and the file without it as it was.

#include <unistd.h>

#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "cli_errors.hpp"
#include "dataset/csv_dataset.hpp"
#include "simulate_command.hpp"

namespace cdcr::cli {
namespace {

std::string temp_path(const std::string& name) {
  return testing::TempDir() + "cdcr_simulate_" + name + "_" + std::to_string(getpid()) + ".csv";
}

std::string text_of(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

// The message the command refuses `options` with; fails the test if it runs.
std::string refusal(const SimulateCommandOptions& options) {
  try {
    run_simulate(options);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted";
  return "";
}

TEST(SimulateHysteresis, WritesAMotionSequence) {
  SimulateCommandOptions options;
  options.samples = 25;
  options.hysteresis = true;
  options.out_path = temp_path("sequence");
  const CommandOutput output = run_simulate(options);
  EXPECT_NE(output.text.find("hysteresis moves the tip"), std::string::npos) << output.text;
  const dataset::Dataset data = dataset::read_dataset_csv(*options.out_path, dataset::PoseColumns::required);
  ASSERT_TRUE(data.has_time);
  EXPECT_EQ(data.sample_count(), 25);
  EXPECT_EQ(data.session_starts, (std::vector<int>{0}));
  EXPECT_GT(data.time_s[0], 0.0);  // t = 0 at home: the first row is a move and a settling later
  const std::string text = text_of(*options.out_path);
  EXPECT_NE(text.find("# motion sequence (column t_s"), std::string::npos);
  EXPECT_NE(text.find("\nt_s,l1_1,"), std::string::npos);
}

TEST(SimulateHysteresis, RefusesAPayloadWithTheSequence) {
  SimulateCommandOptions options;
  options.samples = 5;
  options.hysteresis = true;
  options.payload_range_kg = "0,1";
  EXPECT_EQ(refusal(options),
            "--hysteresis records a motion sequence (a t_s column), which cannot carry a payload column: drop "
            "--payload-range");
}

TEST(SimulateHysteresis, TheLagRangeNeedsTheHysteresisAndAnOrderedRange) {
  SimulateCommandOptions options;
  options.samples = 5;
  options.hysteresis_lag_mm = "0.4,0.7";
  EXPECT_THROW(run_simulate(options), InputError);
  options.hysteresis = true;
  options.hysteresis_lag_mm = "0.7,0.4";
  EXPECT_EQ(refusal(options), "--hysteresis-lag must satisfy 0 <= LO <= HI (got 0.7, 0.4 mm)");
  // No friction, no memory: the tip is where the same commands put it without it.
  options.hysteresis_lag_mm = "0,0";
  options.json = true;
  const CommandOutput output = run_simulate(options);
  EXPECT_NE(output.text.find("\"mean_position_mm\":0.0"), std::string::npos) << output.text;
}

TEST(SimulateHysteresis, WithoutItTheRowsAreSamples) {
  SimulateCommandOptions options;
  options.samples = 5;
  options.out_path = temp_path("samples");
  const CommandOutput output = run_simulate(options);
  EXPECT_EQ(output.text.find("hysteresis"), std::string::npos);
  const std::string text = text_of(*options.out_path);
  EXPECT_EQ(text.find("t_s"), std::string::npos);
  EXPECT_EQ(text.find("hysteresis"), std::string::npos);
  EXPECT_FALSE(dataset::read_dataset_csv(*options.out_path).has_time);
}

}  // namespace
}  // namespace cdcr::cli
