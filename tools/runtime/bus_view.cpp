#include "bus_view.hpp"

#include <cstdio>
#include <thread>

#include "export/binary_file.hpp"
#include "view/view_session.hpp"
#include "view/view_worker.hpp"

namespace cdcr::runtime_host {

BusView::BusView(const std::string& image_path, const ViewChoice& choice, std::uint32_t id_offset,
                 std::vector<hal::CanBus*> listeners)
    : listeners_(std::move(listeners)), scene_rate_hz_(choice.scene_rate_hz) {
  for (hal::CanBus* listener : listeners_) listener->set_filters(nullptr, 0);  // every frame
  view::ViewOptions options;
  options.scene_rate_hz = choice.scene_rate_hz;
  options.id_offset = id_offset;
  const std::vector<std::uint8_t> image =
      image_path.empty() ? std::vector<std::uint8_t>{} : cdcr::exporting::read_binary_file(image_path);
  session_ = std::make_unique<view::ViewSession>(image, options,
                                                 view::ViewOutputs{choice.port, choice.record_path, "cdcr-runtime --sim"});
  if (!session_->view().note().empty()) std::fprintf(stderr, "view: note: %s\n", session_->view().note().c_str());
  if (session_->served()) {
    std::fprintf(stderr,
                 "view: ws://127.0.0.1:%u (Foxglove WebSocket; the simulated loop runs in real time while served)\n",
                 unsigned(session_->port()));
    std::fflush(stderr);
  }
  worker_ = std::make_unique<view::ViewWorker>(session_->view());
  wall_start_ns_ = view::wall_clock_ns();
  steady_start_ = std::chrono::steady_clock::now();
}

BusView::~BusView() {
  if (worker_) worker_->finish();
}

void BusView::take_frames(std::int64_t now_ns) {
  if (session_->served()) std::this_thread::sleep_until(steady_start_ + std::chrono::nanoseconds(now_ns));
  last_ns_ = now_ns;
  const std::uint64_t stamp_ns = wall_start_ns_ + static_cast<std::uint64_t>(now_ns);
  hal::CanFrame frame;
  for (hal::CanBus* listener : listeners_) {
    while (listener->receive(frame) == hal::CanStatus::ok) worker_->push(frame, stamp_ns);
  }
}

void BusView::finish() {
  if (finished_) return;
  finished_ = true;
  worker_->finish();
  const double seconds = double(last_ns_) * 1e-9;
  const view::RobotView& robot_view = session_->view();
  std::printf("view: %ld frames seen (%ld malformed), %ld scenes in %.3f s (%.1f Hz; at most %.0f Hz)\n",
              robot_view.frames(), robot_view.malformed_frames(), robot_view.scenes(), seconds,
              seconds > 0 ? double(robot_view.scenes()) / seconds : 0.0, scene_rate_hz_);
  if (worker_->dropped() > 0) std::printf("view: %ld frames dropped (the view's queue was full)\n", worker_->dropped());
  session_->close_recording();
  if (const std::string report = session_->recording_report(); !report.empty()) std::printf("%s\n", report.c_str());
}

}  // namespace cdcr::runtime_host
