// Simulated time: the timer jumps the clock to each release and counts the
// releases that work ran past.
#include <gtest/gtest.h>

#include <cdcr/sim/lockstep_timer.hpp>

namespace cdcr::sim {
namespace {

TEST(LockstepTimer, ReportsMissedReleases) {
  LockstepClock clock;
  LockstepTimer timer(clock);
  timer.start(1000);
  EXPECT_EQ(timer.wait_next().release_ns, 1000);
  EXPECT_EQ(clock.now_ns(), 1000);
  clock.advance_by(2500);  // work ran into the third period
  const hal::TimerTick tick = timer.wait_next();
  EXPECT_EQ(tick.missed_releases, 2u);
  EXPECT_EQ(tick.release_ns, 4000);
  EXPECT_EQ(timer.overruns(), 2u);
}

}  // namespace
}  // namespace cdcr::sim
