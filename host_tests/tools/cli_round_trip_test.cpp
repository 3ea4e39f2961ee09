// Runs the cdcr executable and reads its --json output back: the forward
// kinematics must reproduce Table 1 of the paper, and the inverse kinematics
// must return cable lengths that drive the model back to its target.

#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/run_cdcr.hpp"

namespace {

using nlohmann::json;

using cdcr::test_support::CliRun;
using cdcr::test_support::run_cdcr;

std::string join(const std::vector<double>& values) {
  std::string text;
  for (const double v : values) {
    std::array<char, 32> digits{};
    std::snprintf(digits.data(), digits.size(), "%.17g", v);
    if (!text.empty()) text += ',';
    text += digits.data();
  }
  return text;
}

std::vector<double> flatten(const json& rows) {
  std::vector<double> values;
  for (const auto& row : rows) {
    for (const auto& v : row) values.push_back(v.get<double>());
  }
  return values;
}

Eigen::Matrix4d matrix_from_json(const json& rows) {
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m(r, c) = rows.at(r).at(c).get<double>();
  }
  return m;
}

const std::string kTable1Case2Cables = "118,123,124,115,124,115,118,121,110,117,125,123,124,105,112,128";

// The paper prints four decimals: agreement means within half a unit of the last.
constexpr double kFourDecimals = 5e-5;

json fk_json(const std::string& geometry, const std::string& cables) {
  const CliRun run = run_cdcr("fk " + geometry + " --cables " + cables + " --json");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err, "");
  return json::parse(run.out);  // throws on anything but a single JSON value
}

void expect_same_pose(const Eigen::Matrix4d& actual, const Eigen::Matrix4d& expected) {
  EXPECT_LT((actual.topLeftCorner<3, 3>() - expected.topLeftCorner<3, 3>()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((actual.topRightCorner<3, 1>() - expected.topRightCorner<3, 1>()).norm(), 1e-6);
}

// ik --json, checked for convergence, then its cables run through fk.
Eigen::Matrix4d pose_of_ik_solution(const std::string& geometry, const std::string& target, bool orientation_given) {
  const CliRun run = run_cdcr("ik " + geometry + " " + target + " --json");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err, "");
  const json result = json::parse(run.out);
  EXPECT_TRUE(result.at("converged").get<bool>());
  EXPECT_LE(result.at("iterations").get<int>(), 100);
  EXPECT_LT(result.at("position_error_mm").get<double>(), 1e-6);
  if (orientation_given) {
    EXPECT_LT(result.at("orientation_error_deg").get<double>(), 1e-6);
  } else {
    EXPECT_EQ(result.at("orientation_error_deg").get<double>(), 0.0);
  }
  EXPECT_EQ(result.at("joints").size(), 4u);
  EXPECT_EQ(result.at("cables").size(), 4u);
  for (const auto& segment : result.at("cables")) EXPECT_EQ(segment.size(), 4u);
  return matrix_from_json(fk_json(geometry, join(flatten(result.at("cables")))).at("pose"));
}

TEST(CliFkJson, ReproducesTable1Case2) {
  const json result = fk_json("--length 120 --radius 70", kTable1Case2Cables);
  ASSERT_TRUE(result.is_object());
  EXPECT_EQ(result.size(), 2u);

  const double expected_joints[4][2] = {{0.9273, 0.0714}, {-2.3562, 0.0606}, {-0.3805, 0.1155}, {-2.0517, 0.1856}};
  const json& joints = result.at("joints");
  ASSERT_EQ(joints.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    ASSERT_EQ(joints.at(i).size(), 2u);
    EXPECT_NEAR(joints.at(i).at(0).get<double>(), expected_joints[i][0], kFourDecimals) << "alpha, segment " << i + 1;
    EXPECT_NEAR(joints.at(i).at(1).get<double>(), expected_joints[i][1], kFourDecimals) << "theta, segment " << i + 1;
  }

  const double expected_pose[3][4] = {{0.9997, 0.0125, 0.0200, 19.2070},
                                      {-0.0084, 0.9814, -0.1917, -6.3962},
                                      {-0.0220, 0.1914, 0.9813, 478.3811}};
  const json& pose = result.at("pose");
  ASSERT_EQ(pose.size(), 4u);
  for (int r = 0; r < 3; ++r) {
    ASSERT_EQ(pose.at(r).size(), 4u);
    for (int c = 0; c < 4; ++c) {
      EXPECT_NEAR(pose.at(r).at(c).get<double>(), expected_pose[r][c], kFourDecimals) << "row " << r << " col " << c;
    }
  }
  EXPECT_EQ(pose.at(3), json::parse("[0.0, 0.0, 0.0, 1.0]"));
}

TEST(CliIkJson, PoseFromFkRoundTrips) {
  for (const std::string geometry : {"--radius 70", ""}) {
    SCOPED_TRACE("geometry: '" + geometry + "'");
    const json fk = fk_json(geometry, kTable1Case2Cables);
    const Eigen::Matrix4d target = matrix_from_json(fk.at("pose"));
    expect_same_pose(pose_of_ik_solution(geometry, "--pose " + join(flatten(fk.at("pose"))), true), target);
  }
}

TEST(CliIkJson, PositionAndQuaternionRoundTrip) {
  const json fk = fk_json("--radius 70", kTable1Case2Cables);
  const Eigen::Matrix4d target = matrix_from_json(fk.at("pose"));
  const Eigen::Quaterniond q(Eigen::Matrix3d(target.topLeftCorner<3, 3>()));
  const std::vector<double> position = {target(0, 3), target(1, 3), target(2, 3)};
  expect_same_pose(
      pose_of_ik_solution("--radius 70", "--position " + join(position) + " --quaternion " + join({q.w(), q.x(), q.y(), q.z()}), true),
      target);
}

TEST(CliIkJson, PositionOnlyReachesThePosition) {
  const json fk = fk_json("--radius 70", kTable1Case2Cables);
  const Eigen::Matrix4d target = matrix_from_json(fk.at("pose"));
  const std::vector<double> position = {target(0, 3), target(1, 3), target(2, 3)};
  const Eigen::Matrix4d reached = pose_of_ik_solution("--radius 70", "--position " + join(position), false);
  EXPECT_LT((reached.topRightCorner<3, 1>() - target.topRightCorner<3, 1>()).norm(), 1e-6);
}

TEST(CliIkJson, UnreachableTargetStillPrintsTheBestResult) {
  // Four 120 mm segments reach at most 480 mm.
  const CliRun run = run_cdcr("ik --position 0,0,500 --json");
  EXPECT_EQ(run.exit_code, 1);
  const json result = json::parse(run.out);
  EXPECT_FALSE(result.at("converged").get<bool>());
  EXPECT_NEAR(result.at("position_error_mm").get<double>(), 20.0, 1e-3);
  EXPECT_EQ(result.at("cables").size(), 4u);
  EXPECT_EQ(run.err.rfind("cdcr: error: target not reached: position error ", 0), 0u) << run.err;
  EXPECT_EQ(run.err.find('\n'), run.err.size() - 1) << "expected exactly one line: " << run.err;
}

}  // namespace
