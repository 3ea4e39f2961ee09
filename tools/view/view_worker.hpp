#pragma once
// The view off the runtime's thread: the loop hands each frame it saw to
// push(), which copies it into a fixed ring and returns (no lock, no
// allocation, no wait); the view's own thread decodes, estimates and
// publishes. So the view costs the runtime's thread a copy per frame and
// nothing else: a slow client or a full ring drops the view's frames (counted),
// never the runtime's cycle.

#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>
#include <vector>

#include <cdcr/hal/can_bus.hpp>

#include "view/robot_view.hpp"

namespace cdcr::view {

class ViewWorker {
 public:
  explicit ViewWorker(RobotView& view);
  ~ViewWorker();  // finish()
  ViewWorker(const ViewWorker&) = delete;
  ViewWorker& operator=(const ViewWorker&) = delete;

  // From one producer thread. False (and counted) when the ring is full.
  bool push(const hal::CanFrame& frame, std::uint64_t time_ns);
  // Handles what is queued and stops the thread.
  void finish();
  long dropped() const { return dropped_; }

 private:
  struct Entry {
    hal::CanFrame frame;
    std::uint64_t time_ns;
  };
  static constexpr std::size_t kCapacity = std::size_t(1) << 16;  // about 6 s of a 1 kHz robot's frames
  void run();

  RobotView& view_;
  std::vector<Entry> ring_;
  std::atomic<std::size_t> head_{0};  // next to write (producer)
  std::atomic<std::size_t> tail_{0};  // next to read (the view's thread)
  std::atomic<bool> stopping_{false};
  long dropped_ = 0;
  std::thread thread_;
};

}  // namespace cdcr::view
