// The one release schedule every backend's timer keeps: the releases a late
// arrival skips, both ways of serving one, and the running count.
#include <gtest/gtest.h>

#include <cdcr/hal/release_schedule.hpp>

namespace cdcr::hal {
namespace {

TEST(ReleaseSchedule, TakesReleasesOnePeriodApart) {
  ReleaseSchedule schedule;
  schedule.start(1000, 250);
  EXPECT_EQ(schedule.take(), 1000);
  EXPECT_EQ(schedule.take(), 1250);
  EXPECT_EQ(schedule.next_release(), 1500);
  EXPECT_EQ(schedule.period(), 250);
}

// A timer that waits: arriving exactly at a release misses nothing; one
// nanosecond after it, that release is missed and the next one waited for.
TEST(ReleaseSchedule, SkipPastMissesEveryReleaseBeforeNow) {
  ReleaseSchedule schedule;
  schedule.start(1000, 1000);
  EXPECT_EQ(schedule.skip_past(1000), 0u);
  EXPECT_EQ(schedule.skip_past(500), 0u);
  EXPECT_EQ(schedule.next_release(), 1000);
  EXPECT_EQ(schedule.skip_past(3001), 3u);  // 1000, 2000, 3000
  EXPECT_EQ(schedule.take(), 4000);
  EXPECT_EQ(schedule.skip_past(5000), 0u);
  EXPECT_EQ(schedule.take(), 5000);
  EXPECT_EQ(schedule.missed_total(), 3u);
}

// A timer that cannot wait serves the latest release that has come, late.
TEST(ReleaseSchedule, SkipToLatestServesTheLatestReleaseThatCame) {
  ReleaseSchedule schedule;
  schedule.start(0, 1000);
  EXPECT_EQ(schedule.skip_to_latest(999), 0u);  // release 0, 999 ns late
  EXPECT_EQ(schedule.take(), 0);
  EXPECT_EQ(schedule.skip_to_latest(1999), 0u);  // release 1000
  EXPECT_EQ(schedule.take(), 1000);
  EXPECT_EQ(schedule.skip_to_latest(5500), 3u);  // 2000, 3000 and 4000 missed: 5000 served
  EXPECT_EQ(schedule.take(), 5000);
  EXPECT_EQ(schedule.missed_total(), 3u);
}

TEST(ReleaseSchedule, SkipToLatestInPeriodsAsTheSysTickCountsThem) {
  ReleaseSchedule schedule;
  schedule.start(1, 1);
  EXPECT_EQ(schedule.skip_to_latest(1), 0u);
  EXPECT_EQ(schedule.take(), 1);
  EXPECT_EQ(schedule.skip_to_latest(5), 3u);  // periods 2, 3, 4
  EXPECT_EQ(schedule.take(), 5);
  EXPECT_EQ(schedule.next_release(), 6);
}

TEST(ReleaseSchedule, StartResetsTheCount) {
  ReleaseSchedule schedule;
  schedule.start(0, 10);
  EXPECT_EQ(schedule.skip_past(100), 10u);
  schedule.start(100, 10);
  EXPECT_EQ(schedule.missed_total(), 0u);
  EXPECT_EQ(schedule.next_release(), 100);
}

TEST(ReleaseSchedule, WithoutAPeriodNothingIsSkipped) {
  ReleaseSchedule schedule;
  schedule.start(0, 0);
  EXPECT_EQ(schedule.skip_past(1'000'000), 0u);
  EXPECT_EQ(schedule.skip_to_latest(1'000'000), 0u);
}

TEST(ReleaseSchedule, AMissCountBeyond32BitsSaturates) {
  ReleaseSchedule schedule;
  schedule.start(0, 1);
  EXPECT_EQ(schedule.skip_past(std::int64_t(1) << 40), 0xFFFFFFFFu);
  EXPECT_EQ(schedule.next_release(), std::int64_t(1) << 40);
}

}  // namespace
}  // namespace cdcr::hal
