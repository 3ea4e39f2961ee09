// The five worked examples of the paper's Table 1 (L = 120 mm, r = 70 mm,
// four segments): sixteen cable lengths -> joint variables -> tip pose.
// The table prints four decimals, so a correct model agrees with every entry
// to within half a unit of the last printed digit.

#include <array>
#include <cmath>
#include <ostream>
#include <string>

#include <gtest/gtest.h>

#include "cdcr/model/kinematics.hpp"

namespace cdcr::model {
namespace {

constexpr int kSegmentCount = 4;
constexpr double kBackboneLengthMm = 120.0;
constexpr double kAnchorRadiusMm = 70.0;

// Half a unit in the fourth decimal, plus room for the binary representation
// of a printed decimal value.
constexpr double kPrintedTolerance = 0.5e-4 + 1e-9;

struct Table1Case {
  const char* name;
  std::array<double, 4 * kSegmentCount> cables_mm;
  std::array<double, 2 * kSegmentCount> joints;  // (alpha, theta) per segment
  std::array<double, 12> pose_rows;              // top three rows of the 4x4 pose, row by row
};

void PrintTo(const Table1Case& c, std::ostream* os) { *os << c.name; }

const Table1Case kTable1[] = {
    {"case1_straight",
     {120, 120, 120, 120, 120, 120, 120, 120, 120, 120, 120, 120, 120, 120, 120, 120},
     {0, 0, 0, 0, 0, 0, 0, 0},
     {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 480}},
    {"case2",
     {118, 123, 124, 115, 124, 115, 118, 121, 110, 117, 125, 123, 124, 105, 112, 128},
     {0.9273, 0.0714, -2.3562, 0.0606, -0.3805, 0.1155, -2.0517, 0.1856},
     {0.9997, 0.0125, 0.0200, 19.2070, -0.0084, 0.9814, -0.1917, -6.3962, -0.0220, 0.1914, 0.9813, 478.3811}},
    {"case3",
     {124, 121, 114, 117, 122, 113, 116, 125, 112, 119, 126, 123, 121, 128, 112, 110},
     {2.7611, 0.0769, -2.0344, 0.0959, -0.2783, 0.1040, 2.0344, 0.1439},
     {0.9969, -0.0028, -0.0789, -28.6431, 0.0062, 0.9991, 0.0428, -11.1228, 0.0787, -0.0432, 0.9960, 478.4405}},
    {"case4",
     {128, 114, 110, 125, 124, 116, 113, 126, 121, 116, 117, 123, 124, 118, 115, 122},
     // The paper prints +2.0899 for segment 3. Its cables (121, 116, 117, 123)
     // give l2 - l4 = -7 and l3 - l1 = -4, a bending plane in the third
     // quadrant, and the printed pose is only reproduced with -2.0899 (see
     // Table1Erratum below), so the sign is a misprint.
     {-2.5930, 0.1508, -2.4038, 0.1062, -2.0899, 0.0576, -2.7234, 0.0704},
     {0.9555, -0.0354, -0.2928, -85.4021, -0.0325, 0.9741, -0.2237, -64.3812, 0.2931, 0.2232, 0.9296, 465.2294}},
    {"case5",
     {125, 110, 112, 127, 114, 118, 127, 124, 114, 115, 125, 123, 123, 127, 117, 114},
     {-2.2236, 0.1530, -0.4324, 0.1023, -0.6288, 0.0972, 2.0032, 0.1023},
     {0.9993, -0.0107, 0.0358, 0.6157, 0.0152, 0.9917, -0.1277, -68.0789, -0.0341, 0.1282, 0.9912, 473.7015}},
};

template <typename S>
RobotGeometry<S> table1_geometry() {
  return RobotGeometry<S>::uniform(kSegmentCount, S(kBackboneLengthMm), S(kAnchorRadiusMm));
}

template <typename S>
CableVector<S> table1_cables(const Table1Case& c) {
  CableVector<S> cables(4 * kSegmentCount);
  for (int i = 0; i < 4 * kSegmentCount; ++i) cables[i] = S(c.cables_mm[i]);
  return cables;
}

Mat4<double> table1_pose(const Table1Case& c) {
  Mat4<double> pose = Mat4<double>::Identity();
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 4; ++col) pose(row, col) = c.pose_rows[4 * row + col];
  }
  return pose;
}

// Joints and pose computed by the model at full precision of S.
template <typename S>
struct ModelOutput {
  JointVector<S> joints;
  Pose<S> tip;
};

template <typename S>
ModelOutput<S> run_model(const Table1Case& c) {
  const RobotGeometry<S> geometry = table1_geometry<S>();
  ModelOutput<S> out;
  EXPECT_EQ(joints_from_cables(table1_cables<S>(c), geometry, out.joints), Status::ok);
  EXPECT_EQ(forward_kinematics(out.joints, geometry, out.tip), Status::ok);
  return out;
}

class Table1 : public ::testing::TestWithParam<Table1Case> {};

TEST_P(Table1, JointsMatchTable) {
  const Table1Case& c = GetParam();
  const ModelOutput<double> out = run_model<double>(c);
  ASSERT_EQ(out.joints.size(), 2 * kSegmentCount);
  for (int i = 0; i < 2 * kSegmentCount; ++i) {
    EXPECT_NEAR(out.joints[i], c.joints[i], kPrintedTolerance) << "joint " << i;
  }
}

TEST_P(Table1, PoseMatchesTable) {
  const Table1Case& c = GetParam();
  const ModelOutput<double> out = run_model<double>(c);
  const Mat4<double> expected = table1_pose(c);
  const Mat4<double> actual = out.tip.matrix();
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) {
      EXPECT_NEAR(actual(row, col), expected(row, col), kPrintedTolerance) << "entry (" << row << ", " << col << ")";
    }
  }
}

TEST_P(Table1, CablesFromJointsReproduceInputDifferences) {
  // Closes the loop through eq. (2). Only the differences l3 - l1 and l2 - l4
  // carry the bend; the table's cable sets are not all of the form (2) (their
  // pair sums differ, e.g. 118 + 124 != 123 + 115), so the lengths themselves
  // are not expected back.
  const Table1Case& c = GetParam();
  const ModelOutput<double> out = run_model<double>(c);
  CableVector<double> cables;
  ASSERT_EQ(cables_from_joints(out.joints, table1_geometry<double>(), cables), Status::ok);
  const CableVector<double> input = table1_cables<double>(c);
  for (int i = 0; i < kSegmentCount; ++i) {
    EXPECT_NEAR(cables[4 * i + 2] - cables[4 * i], input[4 * i + 2] - input[4 * i], 1e-11) << "segment " << i;
    EXPECT_NEAR(cables[4 * i + 1] - cables[4 * i + 3], input[4 * i + 1] - input[4 * i + 3], 1e-11) << "segment " << i;
  }
}

// The float path reads the same integer cable lengths exactly. One float
// rounding is 6e-8 relative, 3e-5 mm on a 480 mm tip; the chain of asin,
// Rodrigues and four pose products stays within a few such roundings (about
// 3e-5 mm, 1e-7 on rotation entries and 2e-7 rad on joints in these cases).
// The bounds below allow several times that and still catch any formula or
// type mistake in the float instantiation, which would show up at 1e-3 or more.
constexpr double kFloatPositionToleranceMm = 2e-4;
constexpr double kFloatUnitlessTolerance = 2e-6;

TEST_P(Table1, FloatPathMatchesDoublePath) {
  const Table1Case& c = GetParam();
  const ModelOutput<double> reference = run_model<double>(c);
  const ModelOutput<float> out = run_model<float>(c);
  ASSERT_EQ(out.joints.size(), 2 * kSegmentCount);
  for (int i = 0; i < kSegmentCount; ++i) {
    // Compare bend vectors: alpha of a straight segment (case 1) is arbitrary.
    const Vec2<double> b = bend_from_joints(segment_joints(out.joints.cast<double>().eval(), i));
    const Vec2<double> b_ref = bend_from_joints(segment_joints(reference.joints, i));
    EXPECT_LE((b - b_ref).norm(), kFloatUnitlessTolerance) << "segment " << i;
  }
  EXPECT_LE((out.tip.rotation.cast<double>() - reference.tip.rotation).cwiseAbs().maxCoeff(), kFloatUnitlessTolerance);
  EXPECT_LE((out.tip.position_mm.cast<double>() - reference.tip.position_mm).norm(), kFloatPositionToleranceMm);
}

TEST_P(Table1, FloatPathMatchesTable) {
  const Table1Case& c = GetParam();
  const ModelOutput<float> out = run_model<float>(c);
  for (int i = 0; i < 2 * kSegmentCount; ++i) {
    EXPECT_NEAR(out.joints[i], c.joints[i], kPrintedTolerance + kFloatUnitlessTolerance) << "joint " << i;
  }
  const Mat4<double> expected = table1_pose(c);
  const Mat4<double> actual = out.tip.matrix().cast<double>();
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) {
      EXPECT_NEAR(actual(row, col), expected(row, col), kPrintedTolerance + kFloatUnitlessTolerance)
          << "entry (" << row << ", " << col << ")";
    }
    EXPECT_NEAR(actual(row, 3), expected(row, 3), kPrintedTolerance + kFloatPositionToleranceMm) << "position " << row;
  }
}

// Forward kinematics of the table's own rounded joints. Rounding each joint
// to 5e-5 rad moves a 480 mm tip by up to a few 1e-2 mm, so this comparison
// is coarse; it only has to tell the two signs apart, which differ by
// several millimetres.
TEST(Table1Erratum, Case4Segment3AlphaSignIsMisprinted) {
  const Table1Case& c = kTable1[3];
  const RobotGeometry<double> geometry = table1_geometry<double>();
  const Mat4<double> expected = table1_pose(c);
  JointVector<double> joints(2 * kSegmentCount);
  for (int i = 0; i < 2 * kSegmentCount; ++i) joints[i] = c.joints[i];

  Pose<double> corrected;
  ASSERT_EQ(forward_kinematics(joints, geometry, corrected), Status::ok);
  EXPECT_LE((corrected.matrix() - expected).cwiseAbs().maxCoeff(), 0.05);

  joints[4] = 2.0899;  // as printed
  Pose<double> as_printed;
  ASSERT_EQ(forward_kinematics(joints, geometry, as_printed), Status::ok);
  EXPECT_GT((as_printed.position_mm - expected.topRightCorner<3, 1>()).norm(), 1.0);
}

INSTANTIATE_TEST_SUITE_P(PaperTable1, Table1, ::testing::ValuesIn(kTable1),
                         [](const ::testing::TestParamInfo<Table1Case>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace cdcr::model
