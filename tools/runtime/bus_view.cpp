#include "bus_view.hpp"

#include <cstdio>
#include <thread>

#include "export/binary_file.hpp"
#include "view/foxglove_server.hpp"
#include "view/robot_view.hpp"
#include "view/view_recording.hpp"
#include "view/view_worker.hpp"

namespace cdcr::runtime_host {

BusView::BusView(const std::string& image_path, const ViewChoice& choice, std::uint32_t id_offset,
                 std::vector<hal::CanBus*> listeners)
    : listeners_(std::move(listeners)), sinks_(std::make_unique<view::SinkList>()), record_path_(choice.record_path),
      scene_rate_hz_(choice.scene_rate_hz) {
  for (hal::CanBus* listener : listeners_) listener->set_filters(nullptr, 0);  // every frame
  if (choice.port >= 0) {
    server_ = std::make_unique<view::FoxgloveServer>(static_cast<std::uint16_t>(choice.port), "cdcr-runtime --sim");
    std::fprintf(stderr,
                 "view: ws://127.0.0.1:%u (Foxglove WebSocket; the simulated loop runs in real time while served)\n",
                 unsigned(server_->port()));
    std::fflush(stderr);
    sinks_->add(server_.get());
  }
  if (!choice.record_path.empty()) {
    recording_ = std::make_unique<view::ViewRecording>(choice.record_path);
    sinks_->add(recording_.get());
  }
  view::ViewOptions options;
  options.scene_rate_hz = choice.scene_rate_hz;
  options.id_offset = id_offset;
  const std::vector<std::uint8_t> image =
      image_path.empty() ? std::vector<std::uint8_t>{} : cdcr::exporting::read_binary_file(image_path);
  view_ = std::make_unique<view::RobotView>(image, options, *sinks_);
  if (!view_->note().empty()) std::fprintf(stderr, "view: note: %s\n", view_->note().c_str());
  worker_ = std::make_unique<view::ViewWorker>(*view_);
  wall_start_ns_ = static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count());
  steady_start_ = std::chrono::steady_clock::now();
}

BusView::~BusView() {
  if (worker_) worker_->finish();
}

void BusView::take_frames(std::int64_t now_ns) {
  if (server_) std::this_thread::sleep_until(steady_start_ + std::chrono::nanoseconds(now_ns));
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
  std::printf("view: %ld frames seen (%ld malformed), %ld scenes in %.3f s (%.1f Hz; at most %.0f Hz)\n",
              view_->frames(), view_->malformed_frames(), view_->scenes(), seconds,
              seconds > 0 ? double(view_->scenes()) / seconds : 0.0, scene_rate_hz_);
  if (worker_->dropped() > 0) std::printf("view: %ld frames dropped (the view's queue was full)\n", worker_->dropped());
  if (recording_) {
    recording_->close();
    std::printf("recording: %s, %llu messages (MCAP; open it in Foxglove, Lichtblick or PlotJuggler)\n",
                record_path_.c_str(), static_cast<unsigned long long>(recording_->message_count()));
  }
}

}  // namespace cdcr::runtime_host
