// The dataset CSV's time column: a file that starts with t_s is a motion
// sequence (rows in the order the robot moved through them), split into
// sessions at pauses longer than kSessionGapSeconds, and that the writer
// writes the time back. The reader's refusals are in csv_dataset_test.cpp.

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "dataset/csv_dataset.hpp"

namespace {

using namespace cdcr::dataset;  // the reader and writer under test

const std::string kTimeCables = "t_s,l1_1,l1_2,l1_3,l1_4\n";
const std::string kTimePoses = "t_s,l1_1,l1_2,l1_3,l1_4,x,y,z,qw,qx,qy,qz\n";

TEST(DatasetTimeColumn, WithoutItTheRowsAreIndependentSamples) {
  const Dataset data = parse_dataset_csv("l1_1,l1_2,l1_3,l1_4\n1,2,3,4\n5,6,7,8\n");
  EXPECT_FALSE(data.has_time);
  EXPECT_EQ(data.time_s.size(), 0);
  EXPECT_TRUE(data.session_starts.empty());
}

TEST(DatasetTimeColumn, ATimeColumnFirstMakesAMotionSequence) {
  const Dataset data = parse_dataset_csv(kTimePoses +
                                         "0.5,1,2,3,4,10,11,12,1,0,0,0\n"
                                         "1.25,5,6,7,8,20,21,22,1,0,0,0\n");
  ASSERT_TRUE(data.has_time);
  EXPECT_EQ(data.segment_count, 1);
  EXPECT_EQ(data.time_s, Eigen::Vector2d(0.5, 1.25));
  EXPECT_EQ(data.session_starts, (std::vector<int>{0}));
  // The time is not a cable: the cables and poses are where they would be without it.
  Eigen::MatrixXd cables(2, 4);
  cables << 1, 2, 3, 4, 5, 6, 7, 8;
  EXPECT_EQ(data.cables_mm, cables);
  ASSERT_TRUE(data.has_poses);
  EXPECT_EQ(data.poses[1].position_mm, Eigen::Vector3d(20, 21, 22));
}

// A pause longer than the gap starts a session; one of exactly the gap does not.
TEST(DatasetTimeColumn, AGapLongerThanTheThresholdStartsASession) {
  ASSERT_EQ(kSessionGapSeconds, 30.0);
  const Dataset data = parse_dataset_csv(kTimeCables +
                                         "0,1,2,3,4\n"
                                         "1,1,2,3,4\n"
                                         "31,1,2,3,4\n"           // 30 s later: the same session
                                         "61.000001,1,2,3,4\n"    // just over 30 s: a new one
                                         "62,1,2,3,4\n"
                                         "1000,1,2,3,4\n");
  EXPECT_EQ(data.session_starts, (std::vector<int>{0, 3, 5}));
  EXPECT_EQ(session_starts_from_times(data.time_s), data.session_starts);
}

Dataset sequence(const std::vector<double>& times) {
  Dataset data;
  data.segment_count = 1;
  data.cables_mm.resize(static_cast<Eigen::Index>(times.size()), 4);
  data.time_s.resize(static_cast<Eigen::Index>(times.size()));
  for (std::size_t r = 0; r < times.size(); ++r) {
    const auto i = static_cast<Eigen::Index>(r);
    data.cables_mm.row(i) << 120.0 + 0.1 * r, 119.0, 121.0 - 0.3 * r, 118.5;
    data.time_s[i] = times[r];
  }
  data.has_time = true;
  data.session_starts = session_starts_from_times(data.time_s);
  return data;
}

TEST(DatasetTimeColumn, TheWriterWritesTheTimeFirstAndItReadsBackExactly) {
  const Dataset data = sequence({0.1, 0.30000000000000004, 2.5, 100.0, 100.7});
  const std::string text = format_dataset_csv(data);
  EXPECT_EQ(text.rfind("t_s,l1_1,l1_2,l1_3,l1_4\n0.10000000000000001,", 0), 0u) << text;
  const Dataset back = parse_dataset_csv(text);
  ASSERT_TRUE(back.has_time);
  EXPECT_EQ(back.time_s, data.time_s);
  EXPECT_EQ(back.cables_mm, data.cables_mm);
  EXPECT_EQ(back.session_starts, (std::vector<int>{0, 3}));

  // Without the flag nothing is written.
  Dataset samples = data;
  samples.has_time = false;
  EXPECT_EQ(format_dataset_csv(samples).rfind("l1_1,", 0), 0u);
}

TEST(DatasetTimeColumn, TheWriterRefusesWhatTheReaderWouldNotReadBack) {
  Dataset going_back = sequence({1.0, 2.0, 3.0});
  going_back.time_s[2] = 2.0;
  EXPECT_THROW(format_dataset_csv(going_back), std::invalid_argument);

  Dataset short_time = sequence({1.0, 2.0, 3.0});
  short_time.time_s.conservativeResize(2);
  EXPECT_THROW(format_dataset_csv(short_time), std::invalid_argument);

  Dataset with_payload = sequence({1.0, 2.0});
  with_payload.has_payload = true;
  with_payload.payload_kg = Eigen::Vector2d(0.1, 0.2);
  EXPECT_THROW(format_dataset_csv(with_payload), std::invalid_argument);

  // A session start the time does not show would be lost on reading.
  Dataset hidden_session = sequence({1.0, 2.0, 3.0});
  hidden_session.session_starts = {0, 2};
  EXPECT_THROW(format_dataset_csv(hidden_session), std::invalid_argument);
}

}  // namespace
