// A faulty link between two CAN interfaces, for the deploy test: every
// frame from the first reaches the second, and the UPDATE_REPORT frames of
// the second reach the first, each lost, sent twice or held back behind
// the next one (at most 20 ms) at random, from a seed.
//   socketcan_relay FROM TO DROP DUPLICATE REORDER SEED
// Runs until SIGTERM, then prints what it did to stderr.

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include <time.h>
#include <unistd.h>

#include <cdcr/firmware/protocol.hpp>

#include "cdcr/linux/socketcan_bus.hpp"

namespace {

volatile std::sig_atomic_t stopping = 0;

void stop(int) { stopping = 1; }

double seconds_now() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return double(now.tv_sec) + 1e-9 * double(now.tv_nsec);
}

struct Faults {
  double drop = 0, duplicate = 0, reorder = 0;
};

// One direction.
class FaultyLink {
 public:
  FaultyLink(const Faults& faults, std::uint32_t seed, cdcr::linux_host::SocketCanBus& to)
      : faults_(faults), random_(seed), to_(to) {}

  void pass(const cdcr::hal::CanFrame& frame) {
    ++frames;
    if (chance(faults_.drop)) {
      ++dropped;
      return;
    }
    const int copies = chance(faults_.duplicate) ? 2 : 1;
    duplicated += copies - 1;
    for (int copy = 0; copy < copies; ++copy) {
      if (holding_) {
        to_.send(frame);
        release();
      } else if (chance(faults_.reorder)) {
        held_ = frame;
        holding_ = true;
        held_at_ = seconds_now();
        ++reordered;
      } else {
        to_.send(frame);
      }
    }
  }
  // A held frame with nothing behind it goes out late rather than never.
  void tick() {
    if (holding_ && seconds_now() - held_at_ > 0.02) release();
  }

  unsigned frames = 0, dropped = 0, duplicated = 0, reordered = 0;

 private:
  bool chance(double p) { return p > 0 && std::uniform_real_distribution<double>(0, 1)(random_) < p; }
  void release() {
    to_.send(held_);
    holding_ = false;
  }

  Faults faults_;
  std::mt19937 random_;
  cdcr::linux_host::SocketCanBus& to_;
  cdcr::hal::CanFrame held_;
  bool holding_ = false;
  double held_at_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 7) {
    std::fprintf(stderr, "usage: socketcan_relay FROM TO DROP DUPLICATE REORDER SEED\n");
    return 2;
  }
  cdcr::linux_host::SocketCanBus from, to;
  std::string error;
  if (!from.open(argv[1], error) || !to.open(argv[2], error)) {
    std::fprintf(stderr, "socketcan_relay: %s\n", error.c_str());
    return 1;
  }
  const cdcr::hal::CanFilter reports[] = {cdcr::firmware::protocol::kUpdateReportFrames};
  to.set_filters(reports, 1);
  const Faults faults{std::atof(argv[3]), std::atof(argv[4]), std::atof(argv[5])};
  const auto seed = static_cast<std::uint32_t>(std::strtoul(argv[6], nullptr, 10));
  FaultyLink forward(faults, seed, to);
  FaultyLink back(faults, seed ^ 0x5A5A5A5Au, from);
  std::signal(SIGTERM, stop);
  std::signal(SIGINT, stop);
  while (!stopping) {
    bool moved = false;
    cdcr::hal::CanFrame frame;
    while (from.receive(frame) == cdcr::hal::CanStatus::ok) {
      forward.pass(frame);
      moved = true;
    }
    while (to.receive(frame) == cdcr::hal::CanStatus::ok) {
      back.pass(frame);
      moved = true;
    }
    forward.tick();
    back.tick();
    if (!moved) usleep(200);
  }
  std::fprintf(stderr, "%u frames to %s (%u lost, %u repeated, %u reordered), %u back (%u lost, %u repeated, %u reordered)\n",
               forward.frames, argv[2], forward.dropped, forward.duplicated, forward.reordered, back.frames,
               back.dropped, back.duplicated, back.reordered);
  return 0;
}
