// The Linux backends on the host itself: what needs no CAN support in the
// kernel (the bus test in User-Mode Linux covers the rest).

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "cdcr/linux/mapped_model_storage.hpp"
#include "cdcr/linux/posix_time.hpp"
#include "cdcr/linux/socketcan_bus.hpp"

namespace cdcr::linux_host {
namespace {

std::string temporary_file(const std::string& name, const std::string& content) {
  const std::string path = ::testing::TempDir() + name + std::to_string(::getpid());
  std::ofstream(path, std::ios::binary) << content;
  return path;
}

TEST(MappedModelStorage, MapsTheFileReadOnlyAndPageAligned) {
  const std::string path = temporary_file("image", "CDCR-bytes");
  MappedModelStorage storage;
  std::string error;
  ASSERT_TRUE(storage.map_file(path, error)) << error;
  const hal::MemoryRegion region = storage.model_region();
  ASSERT_EQ(region.size_bytes, 10u);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(region.data), region.size_bytes), "CDCR-bytes");
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(region.data) % 8, 0u);
  std::remove(path.c_str());
}

TEST(MappedModelStorage, EmptyFileIsAnEmptyRegion) {
  const std::string path = temporary_file("empty", "");
  MappedModelStorage storage;
  std::string error;
  ASSERT_TRUE(storage.map_file(path, error)) << error;
  EXPECT_EQ(storage.model_region().data, nullptr);
  EXPECT_EQ(storage.model_region().size_bytes, 0u);
  std::remove(path.c_str());
}

TEST(MappedModelStorage, MissingFileIsAnErrorWithoutARegion) {
  MappedModelStorage storage;
  std::string error;
  EXPECT_FALSE(storage.map_file("/nonexistent/model.img", error));
  EXPECT_NE(error.find("/nonexistent/model.img"), std::string::npos);
  EXPECT_EQ(storage.model_region().data, nullptr);
}

// Context switches the thread asked for (a sleep), not those the scheduler
// imposed on it (preemption on a busy host).
long voluntary_switches() {
  rusage usage{};
  getrusage(RUSAGE_THREAD, &usage);
  return usage.ru_nvcsw;
}

std::int64_t thread_cpu_ns() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return std::int64_t(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

// A timer of a 2 ms period on the monotonic clock, waiting as the parameter says.
class PosixPeriodicTimerWaits : public ::testing::TestWithParam<ReleaseWait> {
 protected:
  static constexpr std::int64_t kPeriodNs = 2'000'000;

  // Starts the timer; its first release.
  hal::TimerTick start() {
    timer.start(kPeriodNs);
    return timer.wait_next();
  }

  PosixMonotonicClock clock;
  PosixPeriodicTimer timer{clock, GetParam()};
};
INSTANTIATE_TEST_SUITE_P(Waits, PosixPeriodicTimerWaits, ::testing::Values(ReleaseWait::sleep, ReleaseWait::spin),
                         [](const auto& info) { return info.param == ReleaseWait::sleep ? "sleep" : "spin"; });

TEST_P(PosixPeriodicTimerWaits, ReleasesOnAbsoluteDeadlines) {
  const hal::TimerTick first = start();
  EXPECT_GE(clock.now_ns(), first.release_ns);
  std::int64_t releases = 0;
  const std::int64_t cpu_begin_ns = thread_cpu_ns();
  const long switches_begin = voluntary_switches();
  for (int k = 1; k <= 5; ++k) {
    const hal::TimerTick tick = timer.wait_next();
    // On the period grid, whatever the sleep's own latency was (a busy host
    // may make it miss some, which are then counted).
    releases += 1 + tick.missed_releases;
    EXPECT_EQ(tick.release_ns - first.release_ns, releases * kPeriodNs);
    EXPECT_GE(clock.now_ns(), tick.release_ns);
  }
  // Sleeping gives the core away; spinning keeps it. A busy host preempts a
  // spinning thread as much as it likes, so the spin is judged by the
  // switches it asked for (none), not by the share of the core it got.
  const double cpu_share = double(thread_cpu_ns() - cpu_begin_ns) / double(releases * kPeriodNs);
  if (GetParam() == ReleaseWait::sleep) {
    EXPECT_LT(cpu_share, 0.25);
  } else {
    EXPECT_EQ(voluntary_switches() - switches_begin, 0);
  }
}

TEST_P(PosixPeriodicTimerWaits, CountsEveryMissedRelease) {
  const hal::TimerTick first = start();
  // Come back three and a half periods late: releases 2, 3 and 4 have passed.
  while (clock.now_ns() < first.release_ns + 3 * kPeriodNs + kPeriodNs / 2) {
  }
  const hal::TimerTick late = timer.wait_next();
  EXPECT_GE(late.missed_releases, 3u);
  EXPECT_EQ(late.release_ns - first.release_ns, std::int64_t(late.missed_releases + 1) * kPeriodNs);
  EXPECT_EQ(timer.overruns(), late.missed_releases);
}

TEST(SocketCanBus, MissingInterfaceOrNoAfCanIsAOneLineError) {
  SocketCanBus bus;
  std::string error;
  EXPECT_FALSE(bus.open("cdcrnone0", error));
  EXPECT_FALSE(bus.is_open());
  EXPECT_FALSE(error.empty());
  EXPECT_EQ(error.find('\n'), std::string::npos);
  hal::CanFrame frame;
  EXPECT_EQ(bus.receive(frame), hal::CanStatus::bus_off);
  EXPECT_EQ(bus.send(frame), hal::CanStatus::bus_off);
  EXPECT_EQ(bus.error_counters().tx_dropped, 1u);
}

TEST(SocketCanBus, RefusesFramesBeyondClassicCan) {
  SocketCanBus bus;
  hal::CanFrame frame;
  frame.id = 0x800;
  EXPECT_EQ(bus.send(frame), hal::CanStatus::invalid_frame);
  frame.id = 0x100;
  frame.dlc = 9;
  EXPECT_EQ(bus.send(frame), hal::CanStatus::invalid_frame);
}

}  // namespace
}  // namespace cdcr::linux_host
