// The command-line parsing and validation layer, called directly.

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli_errors.hpp"
#include "fk_command.hpp"
#include "geometry_options.hpp"
#include "ik_target.hpp"
#include "number_list.hpp"
#include "segment_diagnostics.hpp"

namespace cdcr::cli {
namespace {

TEST(NumberList, ParsesPlainSignedAndExponentValues) {
  EXPECT_EQ(parse_number_list("118,123.5,-4,+2,1e2", "--x"), (std::vector<double>{118, 123.5, -4, 2, 100}));
}

TEST(NumberList, AllowsSpacesAroundValues) {
  EXPECT_EQ(parse_number_list(" 1 , 2\t,3 ", "--x"), (std::vector<double>{1, 2, 3}));
}

TEST(NumberList, RejectsMalformedSyntaxAsUsageError) {
  for (const char* text : {"", " ", "1,,2", "1,2,", ",1", "abc", "1 2", "1.2.3", "4x", "+", "--1", "0x10"}) {
    EXPECT_THROW(parse_number_list(text, "--x"), UsageError) << "'" << text << "'";
  }
}

TEST(NumberList, NamesTheOptionAndThePosition) {
  try {
    parse_number_list("1,,2", "--cables");
    FAIL() << "no exception";
  } catch (const UsageError& error) {
    EXPECT_STREQ(error.what(), "--cables: value 2 is empty in '1,,2'");
  }
}

TEST(NumberList, AcceptsNonFiniteTokensForRequireFiniteToReject) {
  const std::vector<double> values = parse_number_list("1,nan,inf", "--x");
  ASSERT_EQ(values.size(), 3u);
  EXPECT_TRUE(std::isnan(values[1]));
  EXPECT_TRUE(std::isinf(values[2]));
  EXPECT_THROW(require_finite(values, "--x"), InputError);
  EXPECT_NO_THROW(require_finite({1.0, 2.0}, "--x"));
}

TEST(NumberList, ValueBeyondDoubleRangeIsInvalidInput) {
  EXPECT_THROW(parse_number_list("1e999", "--x"), InputError);
}

TEST(NumberList, RequireCountReportsExpectedAndActual) {
  try {
    require_count({1.0, 2.0}, 3, "--position", "X,Y,Z in mm");
    FAIL() << "no exception";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "--position: expected 3 values (X,Y,Z in mm), got 2");
  }
}

TEST(Geometry, DefaultsAreThePrototype) {
  const auto geometry = make_geometry(GeometryOptions{}, 4);
  EXPECT_EQ(geometry.segment_count, 4);
  EXPECT_EQ(geometry.segments[3].backbone_length_mm, 120.0);
  EXPECT_EQ(geometry.segments[3].anchor_radius_mm, 67.0);
  EXPECT_DOUBLE_EQ(geometry.segments[3].theta_max_rad, M_PI / 2);
}

TEST(Geometry, RejectsNonPositiveNonFiniteAndOutOfRangeValues) {
  GeometryOptions options;
  options.backbone_length_mm = 0.0;
  EXPECT_THROW(make_geometry(options, 4), InputError);
  options = GeometryOptions{};
  options.anchor_radius_mm = NAN;
  EXPECT_THROW(make_geometry(options, 4), InputError);
  options = GeometryOptions{};
  options.theta_max_rad = 3.5;
  EXPECT_THROW(make_geometry(options, 4), InputError);
  EXPECT_THROW(make_geometry(GeometryOptions{}, 0), InputError);
  EXPECT_THROW(make_geometry(GeometryOptions{}, 9), InputError);
  EXPECT_NO_THROW(make_geometry(GeometryOptions{}, 8));
}

TEST(SegmentDiagnostics, NamesTheSegmentAndTheNumbers) {
  const auto geometry = model::RobotGeometry<double>::uniform(2, 120.0, 70.0);
  model::CableVector<double> cables(8);
  cables << 118, 123, 124, 115, 10, 115, 310, 121;
  try {
    joints_from_cables_checked(cables, geometry);
    FAIL() << "no exception";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(),
                 "segment 2: cable length difference exceeds 4 x anchor radius (|l3-l1| = 300 mm > 280 mm)");
  }
}

TEST(IkTarget, QuaternionIsNormalisedWithinTolerance) {
  const double h = std::sqrt(0.5);
  const model::Mat3<double> rotation = rotation_from_quaternion({h * 1.0005, 0.0, 0.0, h * 1.0005});
  // 90 degrees about z: x -> y.
  EXPECT_NEAR((rotation * model::Vec3<double>::UnitX() - model::Vec3<double>::UnitY()).norm(), 0.0, 1e-15);
  EXPECT_NEAR((rotation.transpose() * rotation - model::Mat3<double>::Identity()).norm(), 0.0, 1e-15);
}

TEST(IkTarget, QuaternionFarFromUnitNormIsRejected) {
  EXPECT_THROW(rotation_from_quaternion({1.002, 0.0, 0.0, 0.0}), InputError);
  EXPECT_THROW(rotation_from_quaternion({0.0, 0.0, 0.0, 0.0}), InputError);
  EXPECT_THROW(rotation_from_quaternion({1.0, 0.0, 0.0}), InputError);
  EXPECT_THROW(rotation_from_quaternion({1.0, 0.0, 0.0, NAN}), InputError);
}

TEST(IkTarget, PoseAcceptsTwelveOrSixteenValues) {
  const std::vector<double> top = {0, -1, 0, 10, 1, 0, 0, 20, 0, 0, 1, 30};
  std::vector<double> full = top;
  full.insert(full.end(), {0, 0, 0, 1});
  for (const auto& values : {top, full}) {
    const model::Pose<double> pose = pose_from_row_major(values);
    EXPECT_EQ(pose.position_mm, model::Vec3<double>(10, 20, 30));
    EXPECT_NEAR(pose.rotation(1, 0), 1.0, 1e-15);
    EXPECT_NEAR(pose.rotation(0, 1), -1.0, 1e-15);
  }
}

TEST(IkTarget, PoseRotationIsProjectedOntoSO3) {
  const double e = 4e-7;  // within the tolerance, but not a rotation
  const model::Pose<double> pose = pose_from_row_major({1 + e, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 - e, 0});
  EXPECT_NEAR((pose.rotation.transpose() * pose.rotation - model::Mat3<double>::Identity()).norm(), 0.0, 1e-15);
  EXPECT_NEAR(pose.rotation.determinant(), 1.0, 1e-15);
}

TEST(IkTarget, PoseRejectsBadMatrices) {
  EXPECT_THROW(pose_from_row_major({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}), InputError);                      // 11 values
  EXPECT_THROW(pose_from_row_major({1, 0, 0, 0, 0, 1.001, 0, 0, 0, 0, 1, 0}), InputError);               // stretched
  EXPECT_THROW(pose_from_row_major({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0}), InputError);                  // reflection
  EXPECT_THROW(pose_from_row_major({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1}), InputError);       // last row
  EXPECT_THROW(pose_from_row_major({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, INFINITY}), InputError);            // not finite
}

TEST(FkCommand, JsonOutputIsOneLineObject) {
  FkCommandOptions options;
  options.cables_mm = "120,120,120,120";
  options.json = true;
  const CommandOutput output = run_fk(options);
  EXPECT_EQ(output.failure, "");
  EXPECT_EQ(output.text, "{\"joints\":[[0.0,0.0]],\"pose\":[[1.0,0.0,0.0,0.0],[0.0,1.0,0.0,0.0],"
                         "[0.0,0.0,1.0,120.0],[0.0,0.0,0.0,1.0]]}\n");
}

}  // namespace
}  // namespace cdcr::cli
