#pragma once
// The view (tools/view) on cdcr-runtime's simulated buses: a listener node of
// its own on each bus, read between cycles and handed to the view's thread
// (view/view_worker.hpp), so that the runtime's cycle and its figures are the
// same with the view as without. Served live (--view), the lockstep loop is
// paced to the wall clock, so that a person sees the robot move at its speed;
// recorded only (--record), it runs as fast as it can.

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <cdcr/hal/can_bus.hpp>

namespace cdcr::view {
class ViewSession;
class ViewWorker;
}  // namespace cdcr::view

namespace cdcr::runtime_host {

struct ViewChoice {
  int port = -1;  // --view PORT (0: any free port); -1: not served
  std::string record_path;  // --record FILE.mcap; empty: not recorded
  double scene_rate_hz = 30;
  bool wanted() const { return port >= 0 || !record_path.empty(); }
};

class BusView {
 public:
  // `listeners`: the view's node on each bus (wire identifiers, shifted by
  // id_offset).
  BusView(const std::string& image_path, const ViewChoice& choice, std::uint32_t id_offset,
          std::vector<hal::CanBus*> listeners);
  ~BusView();
  // What the buses carried up to now (simulated time), stamped on the wall
  // clock of the run's start plus that time; served live, first waits for
  // the wall clock to reach it.
  void take_frames(std::int64_t now_ns);
  // Hands over what is left, closes the recording and prints where it is.
  void finish();

 private:
  std::vector<hal::CanBus*> listeners_;
  double scene_rate_hz_;
  std::unique_ptr<view::ViewSession> session_;
  std::unique_ptr<view::ViewWorker> worker_;
  std::int64_t last_ns_ = 0;
  std::uint64_t wall_start_ns_ = 0;
  std::chrono::steady_clock::time_point steady_start_;
  bool finished_ = false;
};

}  // namespace cdcr::runtime_host
