// The whole training path through the command line: `cdcr simulate` makes a
// training set and, in another session of the same robot, an independent
// test set; `cdcr train` fits and exports; `cdcr eval` runs the exported
// image on the test set as the firmware does. A wrong sign or frame anywhere
// between the measured poses and the image (the error twists, the
// compensation's exponential, the export) leaves the compensated error at or
// above the nominal model's.
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../../support/run_cdcr.hpp"

namespace {

using cdcr::test_support::CliRun;
using cdcr::test_support::run_cdcr;

TEST(TrainEndToEnd, SimulateTrainEvalRemovesMostOfTheError) {
  const std::string dir = testing::TempDir();
  const std::string train = "'" + dir + "end_to_end_train.csv'";
  const std::string test = "'" + dir + "end_to_end_test.csv'";
  const std::string image = "'" + dir + "end_to_end_model.img'";
  CliRun run = run_cdcr("simulate --samples 300 --seed 5 --out " + train);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  run = run_cdcr("simulate --samples 200 --seed 5 --session 2 --out " + test);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  run = run_cdcr("train --data " + train + " --out " + image + " --restarts 1");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  run = run_cdcr("eval --model " + image + " --data " + test + " --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json result = nlohmann::json::parse(run.out);
  ASSERT_EQ(result.at("n").get<int>(), 200);
  const double initial_mm = result.at("initial").at("position_mm").get<double>();
  const double initial_deg = result.at("initial").at("orientation_deg").get<double>();
  const double compensated_mm = result.at("compensated").at("position_mm").get<double>();
  const double compensated_deg = result.at("compensated").at("orientation_deg").get<double>();
  // The simulated robot's error is mostly systematic and the paper's method
  // removes about 90 % of it (Table 2); a quarter left is a wide margin for
  // 300 samples, and far below what a sign error leaves.
  EXPECT_GT(initial_mm, 1.0);
  EXPECT_LT(compensated_mm, 0.25 * initial_mm) << run.out;
  EXPECT_LT(compensated_deg, 0.25 * initial_deg) << run.out;
}

// Held-out rows measure the model, then join the exported fit.
TEST(TrainEndToEnd, TheExportedModelIsFittedOnEveryRow) {
  const std::string dir = testing::TempDir();
  const std::string data = "'" + dir + "every_row.csv'";
  const std::string image = "'" + dir + "every_row.img'";
  ASSERT_EQ(run_cdcr("simulate --samples 60 --seed 9 --out " + data).exit_code, 0);

  CliRun run = run_cdcr("train --data " + data + " --out " + image + " --holdout 10 --restarts 0 --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  nlohmann::json trained = nlohmann::json::parse(run.out);
  EXPECT_EQ(trained.at("training_samples").get<int>(), 50);
  EXPECT_EQ(trained.at("validation_samples").get<int>(), 10);
  EXPECT_EQ(trained.at("fitted_rows").get<int>(), 60);
  EXPECT_FALSE(trained.at("validation").is_null());
  run = run_cdcr("inspect " + image + " --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  nlohmann::json inspected = nlohmann::json::parse(run.out);
  EXPECT_EQ(inspected.at("fitted_rows").get<int>(), 60);
  EXPECT_EQ(inspected.at("metadata").at("validation_samples").get<int>(), 10);

  run = run_cdcr("train --data " + data + " --out " + image + " --holdout 0 --restarts 0 --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  trained = nlohmann::json::parse(run.out);
  EXPECT_EQ(trained.at("training_samples").get<int>(), 60);
  EXPECT_EQ(trained.at("validation_samples").get<int>(), 0);
  EXPECT_EQ(trained.at("fitted_rows").get<int>(), 60);
  EXPECT_TRUE(trained.at("validation").is_null());
  run = run_cdcr("inspect " + image + " --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  inspected = nlohmann::json::parse(run.out);
  EXPECT_EQ(inspected.at("fitted_rows").get<int>(), 60);
  EXPECT_EQ(inspected.at("metadata").at("validation_samples").get<int>(), 0);
  // The image the board runs reproduces the training rows it was fitted on.
  run = run_cdcr("eval --model " + image + " --data " + data + " --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json evaluated = nlohmann::json::parse(run.out);
  EXPECT_LT(evaluated.at("compensated").at("position_mm").get<double>(),
            0.25 * evaluated.at("initial").at("position_mm").get<double>());
}

TEST(TrainEndToEnd, HoldoutsThatLeaveTooLittleAreRefused) {
  const std::string dir = testing::TempDir();
  const std::string data = "'" + dir + "small.csv'";
  const std::string image = "'" + dir + "small.img'";
  ASSERT_EQ(run_cdcr("simulate --samples 12 --seed 9 --out " + data).exit_code, 0);
  CliRun run = run_cdcr("train --data " + data + " --out " + image + " --holdout -1");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(run.err, "cdcr: error: --holdout must not be negative (got -1)\n");
  run = run_cdcr("train --data " + data + " --out " + image + " --holdout 11");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(run.err, "cdcr: error: --holdout 11 leaves 1 of the 12 samples to train on; training needs at least 2\n");
  ASSERT_EQ(run_cdcr("simulate --samples 1 --seed 9 --out " + data).exit_code, 0);
  run = run_cdcr("train --data " + data + " --out " + image + " --holdout 0");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("1 sample; training needs at least 2"), std::string::npos) << run.err;
}

}  // namespace
