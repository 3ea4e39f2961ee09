// The dataset CSV reader and writer: what is accepted, that every rejection is
// one line naming the file line, and that writing then reading loses nothing.

#include <cmath>
#include <cstdio>
#include <fstream>
#include <ostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "dataset/csv_dataset.hpp"
#include "rejection_case.hpp"

namespace {

using namespace cdcr::dataset;  // the reader and writer under test

constexpr const char* kPoseHeader = "l1_1,l1_2,l1_3,l1_4,x,y,z,qw,qx,qy,qz\n";

// Runs the parser and returns the rejection; fails the test if there is none.
DatasetError rejection(const std::string& text, PoseColumns poses = PoseColumns::optional) {
  return cdcr::test_support::refusal([&] { parse_dataset_csv(text, poses); }, text);
}

std::string temp_path(const std::string& name) { return testing::TempDir() + "cdcr_dataset_" + name; }

TEST(DatasetCsv, ParsesCableColumns) {
  const std::string text = "l1_1,l1_2,l1_3,l1_4,l2_1,l2_2,l2_3,l2_4\n120,121.5,119,118.25,1,2,3,4\n-0.5,+2,3e1,.5,5,6,7,8\n";
  const Dataset data = parse_dataset_csv(text);
  EXPECT_EQ(data.segment_count, 2);
  EXPECT_FALSE(data.has_poses);
  EXPECT_TRUE(data.poses.empty());
  ASSERT_EQ(data.sample_count(), 2);
  ASSERT_EQ(data.cables_mm.cols(), 8);
  EXPECT_EQ(data.cables_mm(0, 1), 121.5);
  EXPECT_EQ(data.cables_mm(0, 3), 118.25);
  EXPECT_EQ(data.cables_mm(1, 0), -0.5);
  EXPECT_EQ(data.cables_mm(1, 1), 2.0);
  EXPECT_EQ(data.cables_mm(1, 2), 30.0);
  EXPECT_EQ(data.cables_mm(1, 3), 0.5);
  EXPECT_EQ(data.cables_mm(1, 7), 8.0);
  EXPECT_EQ(data.content_hash, fnv1a64(text));
}

// Three cables a segment, or three and four in one robot; written back
// with the same columns.
TEST(DatasetCsv, SegmentsOfThreeCables) {
  const std::string text = "l1_1,l1_2,l1_3,l2_1,l2_2,l2_3,l2_4\n120,121.5,119,1,2,3,4\n";
  const Dataset data = parse_dataset_csv(text);
  EXPECT_EQ(data.segment_count, 2);
  EXPECT_EQ(data.segment_cables, (std::vector<int>{3, 4}));
  EXPECT_EQ(data.cable_count(), 7);
  ASSERT_EQ(data.cables_mm.cols(), 7);
  EXPECT_EQ(data.cables_mm(0, 2), 119.0);
  EXPECT_EQ(data.cables_mm(0, 3), 1.0);
  const std::string written = format_dataset_csv(data);
  EXPECT_EQ(written.substr(0, written.find('\n') + 1), "l1_1,l1_2,l1_3,l2_1,l2_2,l2_3,l2_4\n");
  const Dataset back = parse_dataset_csv(written);
  EXPECT_EQ(back.segment_cables, data.segment_cables);
  EXPECT_EQ(back.cables_mm, data.cables_mm);
}

TEST(DatasetCsv, ParsesPosesAsHamiltonQuaternionWFirst) {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, -0.5).normalized()));
  char row[256];
  std::snprintf(row, sizeof row, "120,120,120,120,1.5,-2,240,%.17g,%.17g,%.17g,%.17g\n", q.w(), q.x(), q.y(), q.z());
  const Dataset data = parse_dataset_csv(std::string(kPoseHeader) + row, PoseColumns::required);
  ASSERT_TRUE(data.has_poses);
  ASSERT_EQ(data.poses.size(), 1u);
  EXPECT_EQ(data.poses[0].position_mm, Eigen::Vector3d(1.5, -2, 240));
  EXPECT_LT((data.poses[0].rotation - q.toRotationMatrix()).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(DatasetCsv, ParsesThePayloadColumnBetweenCablesAndPoses) {
  const Dataset data = parse_dataset_csv(
      "l1_1,l1_2,l1_3,l1_4,payload_kg,x,y,z,qw,qx,qy,qz\n"
      "120,121,122,123,0.75,1.5,-2,240,1,0,0,0\n"
      "119,120,121,122,0,0,0,241,1,0,0,0\n"
      "118,119,120,121,+2e-1,0,0,242,1,0,0,0\n",
      PoseColumns::required);
  ASSERT_TRUE(data.has_payload);
  ASSERT_TRUE(data.has_poses);
  ASSERT_EQ(data.sample_count(), 3);
  ASSERT_EQ(data.payload_kg.size(), 3);
  EXPECT_EQ(data.payload_kg[0], 0.75);
  EXPECT_EQ(data.payload_kg[1], 0.0);
  EXPECT_EQ(data.payload_kg[2], 0.2);
  // The payload is neither a cable nor part of the pose.
  ASSERT_EQ(data.cables_mm.cols(), 4);
  EXPECT_EQ(data.cables_mm(0, 3), 123.0);
  EXPECT_EQ(data.poses[0].position_mm, Eigen::Vector3d(1.5, -2, 240));
  EXPECT_EQ(data.poses[2].position_mm, Eigen::Vector3d(0, 0, 242));

  // Without poses (replay input), and without the column (no payload).
  const Dataset cables = parse_dataset_csv("l1_1,l1_2,l1_3,l1_4,payload_kg\n120,121,122,123,1.25\n");
  ASSERT_TRUE(cables.has_payload);
  EXPECT_FALSE(cables.has_poses);
  ASSERT_EQ(cables.payload_kg.size(), 1);
  EXPECT_EQ(cables.payload_kg[0], 1.25);
  EXPECT_EQ(cables.cables_mm.row(0), Eigen::RowVector4d(120, 121, 122, 123));
  const Dataset none = parse_dataset_csv(std::string(kPoseHeader) + "120,121,122,123,1,2,3,1,0,0,0\n");
  EXPECT_FALSE(none.has_payload);
  EXPECT_EQ(none.payload_kg.size(), 0);
}

TEST(DatasetCsv, SkipsCommentsAndBlankLinesButCountsThem) {
  const std::string text =
      "# measured 2020-03-01\n"
      "\n"
      "l1_1,l1_2,l1_3,l1_4\n"
      "   # indented comment\n"
      "120,120,120,120\n"
      "\t\n"
      "121,119,120,120\n";
  const Dataset data = parse_dataset_csv(text);
  EXPECT_EQ(data.sample_count(), 2);
  EXPECT_EQ(data.cables_mm(1, 0), 121.0);

  const DatasetError e = rejection(text + "# another\n\n120,120,oops,120\n");
  EXPECT_EQ(e.line(), 10);
  EXPECT_STREQ(e.what(), "line 10: column l1_3: 'oops' is not a number");
}

TEST(DatasetCsv, AcceptsCrlfLineEndings) {
  const std::string lf = "# comment\nl1_1,l1_2,l1_3,l1_4,x,y,z,qw,qx,qy,qz\n120,121,122,123,1,2,3,1,0,0,0\n";
  std::string crlf;
  for (const char c : lf) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  const Dataset a = parse_dataset_csv(lf);
  const Dataset b = parse_dataset_csv(crlf);
  EXPECT_EQ(a.cables_mm, b.cables_mm);
  ASSERT_EQ(b.poses.size(), 1u);
  EXPECT_EQ(b.poses[0].position_mm, a.poses[0].position_mm);
  EXPECT_EQ(b.poses[0].rotation, a.poses[0].rotation);
  EXPECT_EQ(rejection(crlf + "1,2,3\r\n").line(), 4);
  // Without a final newline, too.
  EXPECT_EQ(parse_dataset_csv("l1_1,l1_2,l1_3,l1_4\r\n1,2,3,4").sample_count(), 1);
}

TEST(DatasetCsv, AcceptsUtf8ByteOrderMark) {
  const Dataset data = parse_dataset_csv("\xEF\xBB\xBFl1_1,l1_2,l1_3,l1_4\n1,2,3,4\n");
  EXPECT_EQ(data.sample_count(), 1);
}

using BadCsv = cdcr::test_support::RejectionCase;

class DatasetCsvRejects : public testing::TestWithParam<BadCsv> {};

TEST_P(DatasetCsvRejects, WithOneLineNamingTheLine) {
  const DatasetError e = rejection(GetParam().text);
  cdcr::test_support::expect_refusal_matches(e, GetParam());
  EXPECT_EQ(std::string(e.what()).find_first_of("\r\n"), std::string::npos);
}

const std::string kCables = "l1_1,l1_2,l1_3,l1_4\n";
const std::string kPoses = kPoseHeader;

INSTANTIATE_TEST_SUITE_P(
    Malformed, DatasetCsvRejects,
    testing::Values(
        BadCsv{"too_few_fields", kCables + "1,2,3,4\n1,2,3\n", 3, "line 3: expected 4 fields, found 3"},
        BadCsv{"too_many_fields", kCables + "1,2,3,4,5\n", 2, "line 2: expected 4 fields, found 5"},
        BadCsv{"trailing_comma", kCables + "1,2,3,4,\n", 2, "line 2: expected 4 fields, found 5"},
        BadCsv{"empty_field", kCables + "1,,3,4\n", 2, "line 2: column l1_2: empty field"},
        BadCsv{"blank_field", kCables + "1,2, ,4\n", 2, "line 2: column l1_3: empty field"},
        BadCsv{"text", kCables + "1,2,3,abc\n", 2, "line 2: column l1_4: 'abc' is not a number"},
        BadCsv{"trailing_garbage", kCables + "1.0x,2,3,4\n", 2, "line 2: column l1_1: '1.0x' is not a number"},
        BadCsv{"inner_space", kCables + "1,2 3,3,4\n", 2, "line 2: column l1_2: '2 3' is not a number"},
        BadCsv{"double_sign", kCables + "+-1,2,3,4\n", 2, "line 2: column l1_1: '+-1' is not a number"},
        BadCsv{"hex", kCables + "0x10,2,3,4\n", 2, "line 2: column l1_1: '0x10' is not a number"},
        BadCsv{"decimal_comma", kCables + "1;2;3;4\n", 2, "line 2: expected 4 fields, found 1"},
        BadCsv{"control_byte", kCables + "1,2\x01,3,4\n", 2, "line 2: column l1_2: '2\\x01' is not a number"},
        BadCsv{"out_of_range", kCables + "1e999,2,3,4\n", 2,
               "line 2: column l1_1: '1e999' is out of the range of a double"},
        BadCsv{"long_field", kCables + "1,2,3," + std::string(100, 'z') + "\n", 2,
               "line 2: column l1_4: '" + std::string(40, 'z') + "...' is not a number"}),
    cdcr::test_support::rejection_case_name);

INSTANTIATE_TEST_SUITE_P(
    NotFinite, DatasetCsvRejects,
    testing::Values(BadCsv{"nan_cable", kCables + "nan,2,3,4\n", 2, "line 2: column l1_1: 'nan' is NaN or Inf"},
                    BadCsv{"NaN_cable", kCables + "1,NaN,3,4\n", 2, "line 2: column l1_2: 'NaN' is NaN or Inf"},
                    BadCsv{"inf_cable", kCables + "1,2,inf,4\n", 2, "line 2: column l1_3: 'inf' is NaN or Inf"},
                    BadCsv{"minus_infinity", kCables + "1,2,3,-Infinity\n", 2,
                           "line 2: column l1_4: '-Infinity' is NaN or Inf"},
                    BadCsv{"nan_position", kPoses + "1,2,3,4,nan,0,0,1,0,0,0\n", 2,
                           "line 2: column x: 'nan' is NaN or Inf"},
                    BadCsv{"inf_quaternion", kPoses + "1,2,3,4,0,0,0,1,0,0,inf\n", 2,
                           "line 2: column qz: 'inf' is NaN or Inf"}),
    cdcr::test_support::rejection_case_name);

INSTANTIATE_TEST_SUITE_P(
    Quaternion, DatasetCsvRejects,
    testing::Values(BadCsv{"norm_too_large", kPoses + "1,2,3,4,0,0,0,1.0011,0,0,0\n", 2,
                           "line 2: quaternion norm 1.0011 is not 1 (tolerance 0.001)"},
                    BadCsv{"norm_too_small", kPoses + "1,2,3,4,0,0,0,0.6,0,0.6,0\n", 2,
                           "line 2: quaternion norm 0.848528 is not 1 (tolerance 0.001)"},
                    BadCsv{"zero", kPoses + "1,2,3,4,0,0,0,0,0,0,0\n", 2,
                           "line 2: quaternion norm 0 is not 1 (tolerance 0.001)"},
                    BadCsv{"overflowing_norm", kPoses + "1,2,3,4,0,0,0,1e300,1e300,0,0\n", 2,
                           "line 2: quaternion norm inf is not 1 (tolerance 0.001)"}),
    cdcr::test_support::rejection_case_name);

INSTANTIATE_TEST_SUITE_P(
    Header, DatasetCsvRejects,
    testing::Values(
        BadCsv{"no_header", "120,120,120,120\n", 1,
               "line 1: missing header: the first line must name the columns (l1_1,l1_2,...), found data"},
        BadCsv{"no_header_after_comments", "# data\n\n120,120,120,120\n", 3,
               "line 3: missing header: the first line must name the columns (l1_1,l1_2,...), found data"},
        BadCsv{"two_cables", "l1_1,l1_2\n1,2\n", 1,
               "line 1: header column 2: segment 1 has 2 cable columns; a segment has 3 or 4"},
        BadCsv{"five_cables", "l1_1,l1_2,l1_3,l1_4,l1_5\n1,2,3,4,5\n", 1,
               "line 1: header column 5 is 'l1_5', expected 'l2_1'"},
        BadCsv{"two_cables_then_a_segment", "l1_1,l1_2,l2_1,l2_2,l2_3\n1,2,3,4,5\n", 1,
               "line 1: header column 3: segment 1 has 2 cable columns; a segment has 3 or 4"},
        BadCsv{"no_cable_columns", "x,y,z,qw,qx,qy,qz\n", 1,
               "line 1: header must start with cable columns l1_1,l1_2,l1_3[,l1_4],l2_1,... (three or four a "
               "segment)"},
        BadCsv{"wrong_cable_name", "l1_1,l1_2,l1_3,l2_4\n1,2,3,4\n", 1,
               "line 1: header column 4 is 'l2_4', expected 'l1_4' or 'l2_1'"},
        BadCsv{"segments_out_of_order", "l1_1,l1_2,l1_3,l1_4,l3_1,l3_2,l3_3,l3_4\n", 1,
               "line 1: header column 5 is 'l3_1', expected 'l2_1'"},
        BadCsv{"too_many_segments",
               [] {
                 std::string h;
                 for (int s = 1; s <= 9; ++s)
                   for (int c = 1; c <= 4; ++c) h += (h.empty() ? "" : ",") + ("l" + std::to_string(s) + "_" + std::to_string(c));
                 return h + "\n";
               }(),
               1, "line 1: header column 33 is 'l9_1': more than the 8 segments supported"},
        BadCsv{"missing_pose_column", "l1_1,l1_2,l1_3,l1_4,x,y,z,qw,qx,qy\n", 1, "line 1: missing column 'qz'"},
        BadCsv{"wrong_pose_name", "l1_1,l1_2,l1_3,l1_4,x,y,z,qx,qy,qz,qw\n", 1,
               "line 1: header column 8 is 'qx', expected 'qw'"},
        BadCsv{"extra_column", "l1_1,l1_2,l1_3,l1_4,x,y,z,qw,qx,qy,qz,t\n", 1, "line 1: unexpected column 't'"},
        BadCsv{"no_rows", "# only a header\nl1_1,l1_2,l1_3,l1_4\n\n# nothing\n", 2,
               "line 2: no data rows after the header"},
        BadCsv{"empty", "", 0, "no header line (expected l1_1,l1_2,...): the file is empty or only comments"},
        BadCsv{"only_comments", "# a\n\n# b\n", 0,
               "no header line (expected l1_1,l1_2,...): the file is empty or only comments"}),
    cdcr::test_support::rejection_case_name);

const std::string kPayload = "l1_1,l1_2,l1_3,l1_4,payload_kg\n";
const std::string kPayloadPoses = "l1_1,l1_2,l1_3,l1_4,payload_kg,x,y,z,qw,qx,qy,qz\n";

INSTANTIATE_TEST_SUITE_P(
    Payload, DatasetCsvRejects,
    testing::Values(
        BadCsv{"nan", kPayload + "1,2,3,4,0.5\n1,2,3,4,nan\n", 3, "line 3: column payload_kg: 'nan' is NaN or Inf"},
        BadCsv{"inf", kPayloadPoses + "1,2,3,4,inf,0,0,0,1,0,0,0\n", 2,
               "line 2: column payload_kg: 'inf' is NaN or Inf"},
        BadCsv{"negative", kPayload + "1,2,3,4,0\n1,2,3,4,-0.5\n", 3,
               "line 3: column payload_kg: '-0.5' is negative; a payload is a mass, zero or more kg"},
        BadCsv{"negative_with_poses", kPayloadPoses + "1,2,3,4,-1e-9,0,0,0,1,0,0,0\n", 2,
               "line 2: column payload_kg: '-1e-9' is negative; a payload is a mass, zero or more kg"},
        BadCsv{"empty", kPayload + "1,2,3,4,\n", 2, "line 2: column payload_kg: empty field"},
        BadCsv{"text", kPayload + "1,2,3,4,1kg\n", 2, "line 2: column payload_kg: '1kg' is not a number"},
        BadCsv{"missing_field", kPayloadPoses + "1,2,3,4,0,0,0,1,0,0,0\n", 2, "line 2: expected 12 fields, found 11"},
        BadCsv{"after_the_poses", "l1_1,l1_2,l1_3,l1_4,x,y,z,qw,qx,qy,qz,payload_kg\n1,2,3,4,0,0,0,1,0,0,0,1\n", 1,
               "line 1: header column 12 is 'payload_kg', which belongs right after the cable columns and before "
               "x,y,z,..."},
        BadCsv{"among_the_poses", "l1_1,l1_2,l1_3,l1_4,x,y,z,payload_kg,qw,qx,qy,qz\n", 1,
               "line 1: header column 8 is 'payload_kg', which belongs right after the cable columns and before "
               "x,y,z,..."},
        BadCsv{"among_the_cables", "l1_1,l1_2,payload_kg,l1_3,l1_4,x,y,z,qw,qx,qy,qz\n", 1,
               "line 1: header column 3 is 'payload_kg', which belongs right after the cable columns and before "
               "x,y,z,..."},
        BadCsv{"first", "payload_kg,l1_1,l1_2,l1_3,l1_4\n", 1,
               "line 1: header column 1 is 'payload_kg', which belongs right after the cable columns and before "
               "x,y,z,..."},
        BadCsv{"twice", "l1_1,l1_2,l1_3,l1_4,payload_kg,payload_kg,x,y,z,qw,qx,qy,qz\n", 1,
               "line 1: header column 6 is 'payload_kg', which belongs right after the cable columns and before "
               "x,y,z,..."},
        BadCsv{"misnamed", "l1_1,l1_2,l1_3,l1_4,payload,x,y,z,qw,qx,qy,qz\n", 1,
               "line 1: header column 5 is 'payload', expected 'x'"}),
    cdcr::test_support::rejection_case_name);

// A motion sequence's time column (t_s, first); time_column_test.cpp has
// what it means.
const std::string kTimeCables = "t_s,l1_1,l1_2,l1_3,l1_4\n";

INSTANTIATE_TEST_SUITE_P(
    Time, DatasetCsvRejects,
    testing::Values(
        BadCsv{"going_back", kTimeCables + "1,1,2,3,4\n# a comment\n2,1,2,3,4\n1.5,1,2,3,4\n", 5,
               "line 5: column t_s: '1.5' is not after the previous row's '2'; the time of a motion sequence must "
               "strictly increase"},
        BadCsv{"repeated", kTimeCables + "1,1,2,3,4\n1.0,1,2,3,4\n", 3,
               "line 3: column t_s: '1.0' is not after the previous row's '1'; the time of a motion sequence must "
               "strictly increase"},
        BadCsv{"nan", kTimeCables + "nan,1,2,3,4\n", 2, "line 2: column t_s: 'nan' is NaN or Inf"},
        BadCsv{"empty", kTimeCables + ",1,2,3,4\n", 2, "line 2: column t_s: empty field"},
        BadCsv{"missing_field", kTimeCables + "1,2,3,4\n", 2, "line 2: expected 5 fields, found 4"},
        BadCsv{"with_payload", "t_s,l1_1,l1_2,l1_3,l1_4,payload_kg\n1,1,2,3,4,0.5\n", 1,
               "line 1: a time column (t_s) together with a payload column (payload_kg) is not supported: record a "
               "motion sequence without payload, or payload samples without time"},
        BadCsv{"with_payload_and_poses", "t_s,l1_1,l1_2,l1_3,l1_4,payload_kg,x,y,z,qw,qx,qy,qz\n", 1,
               "line 1: a time column (t_s) together with a payload column (payload_kg) is not supported: record a "
               "motion sequence without payload, or payload samples without time"},
        BadCsv{"after_the_cables", "l1_1,l1_2,l1_3,l1_4,t_s\n1,2,3,4,5\n", 1,
               "line 1: header column 5 is 't_s', which belongs first, before the cable columns"},
        BadCsv{"after_the_poses", "l1_1,l1_2,l1_3,l1_4,x,y,z,qw,qx,qy,qz,t_s\n", 1,
               "line 1: header column 12 is 't_s', which belongs first, before the cable columns"},
        BadCsv{"twice", "t_s,t_s,l1_1,l1_2,l1_3,l1_4\n", 1,
               "line 1: header column 2 is 't_s', which belongs first, before the cable columns"},
        BadCsv{"alone", "t_s\n1\n", 1,
               "line 1: header must start with t_s, then cable columns l1_1,l1_2,l1_3[,l1_4],l2_1,... (three or four "
               "a segment)"}),
    cdcr::test_support::rejection_case_name);

TEST(DatasetCsv, RequiredPoseColumns) {
  const DatasetError e = rejection(kCables + "1,2,3,4\n", PoseColumns::required);
  EXPECT_EQ(e.line(), 1);
  EXPECT_STREQ(e.what(), "line 1: missing pose columns x,y,z,qw,qx,qy,qz after the cable columns");
  const DatasetError p = rejection(kPayload + "1,2,3,4,0.5\n", PoseColumns::required);
  EXPECT_EQ(p.line(), 1);
  EXPECT_STREQ(p.what(), "line 1: missing pose columns x,y,z,qw,qx,qy,qz after the payload column");
}

TEST(DatasetCsv, AcceptsAZeroPayloadOfEitherSign) {
  const Dataset data = parse_dataset_csv(kPayload + "1,2,3,4,-0\n1,2,3,4,0\n");
  EXPECT_EQ(data.payload_kg[0], 0.0);
  EXPECT_EQ(data.payload_kg[1], 0.0);
}

TEST(DatasetCsv, RenormalisesQuaternionsWithinTheTolerance) {
  const Eigen::Quaterniond unit(Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.2, -1, 0.4).normalized()));
  for (const double scale : {1.0009, 0.9991, 1.0 + 1e-12}) {
    const Eigen::Vector4d q = scale * unit.coeffs();  // (x, y, z, w)
    char row[256];
    std::snprintf(row, sizeof row, "1,2,3,4,0,0,0,%.17g,%.17g,%.17g,%.17g\n", q[3], q[0], q[1], q[2]);
    const Dataset data = parse_dataset_csv(kPoses + row);
    const Eigen::Matrix3d r = data.poses.at(0).rotation;
    const double eps = std::numeric_limits<double>::epsilon();
    EXPECT_LE((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 4 * eps) << scale;
    EXPECT_NEAR(r.determinant(), 1.0, 4 * eps) << scale;
    EXPECT_LE((r - unit.toRotationMatrix()).cwiseAbs().maxCoeff(), 4 * eps) << scale;
    // Written back, the quaternion is unit to the last bit or two.
    const Dataset again = parse_dataset_csv(format_dataset_csv(data));
    EXPECT_LE((again.poses[0].rotation - r).cwiseAbs().maxCoeff(), 4 * eps);
  }
}

Dataset random_dataset(int segments, int samples, bool poses, unsigned seed, bool payload = false) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> length(60.0, 180.0);
  std::uniform_real_distribution<double> mass(0.0, 2.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Dataset data;
  data.segment_count = segments;
  data.has_poses = poses;
  data.has_payload = payload;
  data.cables_mm.resize(samples, 4 * segments);
  if (payload) data.payload_kg.resize(samples);
  for (int r = 0; r < samples; ++r) {
    for (int c = 0; c < 4 * segments; ++c) data.cables_mm(r, c) = length(rng);
    if (payload) data.payload_kg[r] = mass(rng);
    if (poses) {
      Eigen::Quaterniond q(gauss(rng), gauss(rng), gauss(rng), gauss(rng));
      q.normalize();
      cdcr::model::Pose<double> pose;
      pose.rotation = q.toRotationMatrix();
      pose.position_mm = Eigen::Vector3d(gauss(rng), gauss(rng), 400 + gauss(rng)) * 37.0;
      data.poses.push_back(pose);
    }
  }
  // Values whose shortest decimal needs all 17 digits, or none.
  data.cables_mm(0, 0) = 0.1 + 0.2;
  data.cables_mm(0, 1) = 1.0 / 3.0;
  data.cables_mm(samples - 1, 0) = -0.0;
  data.cables_mm(samples - 1, 1) = 1e-300;
  data.cables_mm(samples - 1, 2) = 123456789012345.67;
  data.cables_mm(samples - 1, 3) = std::nextafter(120.0, 200.0);
  if (payload) {
    data.payload_kg[0] = 0.1 + 0.2;
    data.payload_kg[1] = 0.0;
    data.payload_kg[samples - 1] = 1e-300;
  }
  return data;
}

TEST(DatasetCsv, FormatThenParseIsExact) {
  for (const bool poses : {false, true}) {
    const Dataset data = random_dataset(3, 40, poses, poses ? 7 : 8);
    const std::string text = format_dataset_csv(data, "first line\nsecond line");
    EXPECT_EQ(text.rfind("# first line\n# second line\nl1_1,", 0), 0u) << text.substr(0, 80);
    const Dataset back = parse_dataset_csv(text, poses ? PoseColumns::required : PoseColumns::optional);
    ASSERT_EQ(back.segment_count, 3);
    ASSERT_EQ(back.has_poses, poses);
    ASSERT_EQ(back.sample_count(), 40);
    for (int r = 0; r < 40; ++r) {
      for (int c = 0; c < 12; ++c) {
        // Bit for bit, the sign of zero included.
        EXPECT_EQ(std::signbit(back.cables_mm(r, c)), std::signbit(data.cables_mm(r, c)));
        EXPECT_EQ(back.cables_mm(r, c), data.cables_mm(r, c)) << r << "," << c;
      }
    }
    ASSERT_EQ(back.poses.size(), data.poses.size());
    for (std::size_t i = 0; i < data.poses.size(); ++i) {
      EXPECT_EQ(back.poses[i].position_mm, data.poses[i].position_mm);
      // The quaternion text is exact; the matrix is rebuilt from it.
      EXPECT_LE((back.poses[i].rotation - data.poses[i].rotation).cwiseAbs().maxCoeff(), 1e-15);
    }
  }
}

TEST(DatasetCsv, FormatThenParseKeepsThePayloadExactly) {
  for (const bool poses : {false, true}) {
    const Dataset data = random_dataset(2, 30, poses, poses ? 11 : 12, true);
    const std::string text = format_dataset_csv(data);
    const std::string header = poses ? "l1_1,l1_2,l1_3,l1_4,l2_1,l2_2,l2_3,l2_4,payload_kg,x,y,z,qw,qx,qy,qz\n"
                                     : "l1_1,l1_2,l1_3,l1_4,l2_1,l2_2,l2_3,l2_4,payload_kg\n";
    EXPECT_EQ(text.rfind(header, 0), 0u) << text.substr(0, 80);
    const Dataset back = parse_dataset_csv(text);
    ASSERT_TRUE(back.has_payload);
    ASSERT_EQ(back.has_poses, poses);
    ASSERT_EQ(back.payload_kg.size(), 30);
    for (int r = 0; r < 30; ++r) EXPECT_EQ(back.payload_kg[r], data.payload_kg[r]) << r;
    EXPECT_EQ(back.cables_mm, data.cables_mm);
    for (std::size_t i = 0; i < data.poses.size(); ++i) EXPECT_EQ(back.poses[i].position_mm, data.poses[i].position_mm);
  }
}

TEST(DatasetCsv, FormatRejectsPayloadsTheReaderWould) {
  Dataset data = random_dataset(1, 3, true, 2, true);
  EXPECT_NO_THROW(format_dataset_csv(data));
  data.payload_kg.resize(2);
  EXPECT_THROW(format_dataset_csv(data), std::invalid_argument);
  for (const double bad : {-0.1, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    data = random_dataset(1, 3, true, 2, true);
    data.payload_kg[1] = bad;
    EXPECT_THROW(format_dataset_csv(data), std::invalid_argument) << bad;
  }
}

TEST(DatasetCsv, FormatRejectsInconsistentShapes) {
  Dataset data = random_dataset(2, 3, true, 1);
  data.poses.pop_back();
  EXPECT_THROW(format_dataset_csv(data), std::invalid_argument);
  data = random_dataset(2, 3, false, 1);
  data.segment_count = 3;
  EXPECT_THROW(format_dataset_csv(data), std::invalid_argument);
}

TEST(DatasetCsv, Fnv1a64TestVectors) {
  EXPECT_EQ(fnv1a64(""), 0xcbf29ce484222325ull);
  EXPECT_EQ(fnv1a64("a"), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(fnv1a64("foobar"), 0x85944171f73967e8ull);
  // Bytes above 0x7f are hashed as unsigned, whatever the signedness of char.
  EXPECT_NE(fnv1a64("\xff"), fnv1a64("\x7f"));
}

TEST(DatasetCsv, WriteThenReadAFile) {
  const Dataset data = random_dataset(4, 10, true, 3);
  const std::string path = temp_path("round_trip.csv");
  write_dataset_csv(path, data, "synthetic");
  const Dataset back = read_dataset_csv(path, PoseColumns::required);
  EXPECT_EQ(back.cables_mm, data.cables_mm);
  EXPECT_EQ(back.content_hash, fnv1a64(format_dataset_csv(data, "synthetic")));
  std::remove(path.c_str());
}

TEST(DatasetCsv, FileErrorsNameThePath) {
  const std::string missing = temp_path("does_not_exist.csv");
  try {
    read_dataset_csv(missing);
    FAIL() << "read a missing file";
  } catch (const DatasetError& e) {
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(std::string(e.what()), missing + ": cannot open file");
  }

  const std::string path = temp_path("bad.csv");
  std::ofstream(path) << "l1_1,l1_2,l1_3,l1_4\n1,2,3,4\n1,2,x,4\n";
  try {
    read_dataset_csv(path);
    FAIL() << "accepted a bad row";
  } catch (const DatasetError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(e.message(), "column l1_3: 'x' is not a number");
    EXPECT_EQ(std::string(e.what()), path + ": line 3: column l1_3: 'x' is not a number");
  }
  std::remove(path.c_str());

  EXPECT_THROW(write_dataset_csv(testing::TempDir() + "no/such/dir/out.csv", random_dataset(1, 2, false, 1)),
               DatasetError);
}

}  // namespace
