#include "view/view_worker.hpp"

#include <chrono>

namespace cdcr::view {

ViewWorker::ViewWorker(RobotView& view) : view_(view), ring_(kCapacity) { thread_ = std::thread([this] { run(); }); }

ViewWorker::~ViewWorker() { finish(); }

bool ViewWorker::push(const hal::CanFrame& frame, std::uint64_t time_ns) {
  const std::size_t head = head_.load(std::memory_order_relaxed);
  if (head - tail_.load(std::memory_order_acquire) >= kCapacity) {
    ++dropped_;
    return false;
  }
  ring_[head % kCapacity] = {frame, time_ns};
  head_.store(head + 1, std::memory_order_release);
  return true;
}

void ViewWorker::run() {
  for (;;) {
    const bool stopping = stopping_.load(std::memory_order_acquire);
    std::size_t tail = tail_.load(std::memory_order_relaxed);
    const std::size_t head = head_.load(std::memory_order_acquire);
    if (tail == head) {
      if (stopping) return;
      // Polled, so that push() never has to wake anyone.
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }
    for (; tail != head; ++tail) {
      const Entry& entry = ring_[tail % kCapacity];
      view_.on_frame(entry.frame, entry.time_ns);
      tail_.store(tail + 1, std::memory_order_release);
    }
  }
}

void ViewWorker::finish() {
  if (!thread_.joinable()) return;
  stopping_.store(true, std::memory_order_release);
  thread_.join();
}

}  // namespace cdcr::view
