#pragma once
// A board on the simulated bus with a simulated flash, for the model update
// tests: the runtime can be reset (rebuilt on the same flash, as after a
// power loss), the drives keep sending cable lengths, and a host sends a
// model with the firmware's UpdateSender (the one `cdcr deploy` uses).

#include <cstring>
#include <memory>
#include <vector>

#include <cdcr/firmware/model_slots.hpp>
#include <cdcr/firmware/runtime.hpp>
#include <cdcr/firmware/update/update_sender.hpp>
#include <cdcr/sim/sim_flash.hpp>

#include "runtime_fixture.hpp"

namespace cdcr::test_support {

using firmware::UpdateSender;

// The frames a sender hands over, kept until the test sends them (or
// changes them first).
class FrameQueue final : public hal::CanBus {
 public:
  std::vector<hal::CanFrame> frames;

  hal::CanStatus send(const hal::CanFrame& frame) override {
    frames.push_back(frame);
    return hal::CanStatus::ok;
  }
  hal::CanStatus receive(hal::CanFrame&) override { return hal::CanStatus::empty; }
  bool set_filters(const hal::CanFilter*, std::size_t) override { return true; }
  hal::CanErrorCounters error_counters() const override { return {}; }

  std::vector<hal::CanFrame> take() {
    std::vector<hal::CanFrame> taken;
    taken.swap(frames);
    return taken;
  }
};

// An image the sender sends from: the sender keeps a pointer to the bytes.
struct SentImage {
  std::vector<std::uint8_t> bytes;
  UpdateSender sender;
  explicit SentImage(std::vector<std::uint8_t> image)
      : bytes(std::move(image)), sender(bytes.data(), static_cast<std::uint32_t>(bytes.size())) {}
};

// Writes `image` into `slot` as committed with `sequence`, as a programmer
// would (no flash operations counted).
inline void provision_slot(sim::SimFlash& flash, int slot, const std::vector<std::uint8_t>& image,
                           std::uint32_t sequence) {
  const firmware::SlotGeometry g = firmware::slot_geometry(flash, slot);
  std::memset(flash.raw() + g.offset, 0xFF, std::size_t(g.sectors) * g.sector_bytes);
  flash.write_raw(g.image_offset(), image.data(), static_cast<std::uint32_t>(image.size()));
  firmware::SlotHeader header;
  header.sequence = sequence;
  header.image_size = static_cast<std::uint32_t>(image.size());
  firmware::sha256(image.data(), image.size(), header.digest);
  std::uint8_t bytes[firmware::kSlotHeaderBytes - 4];
  firmware::encode_header(header, bytes);
  flash.write_raw(g.header_offset(), bytes, sizeof(bytes));
}

struct UpdateBoard {
  sim::SimFlash& flash;
  sim::VirtualCanBus bus;
  sim::LockstepClock clock;
  sim::LockstepTimer timer{clock};
  sim::MemoryModelStorage storage;
  RecordingConsole console;
  hal::Hal hal{clock, timer, bus.node(0), storage, console, &flash};
  hal::CanBus& host_node = bus.node(2);
  std::unique_ptr<firmware::Runtime> runtime;
  std::unique_ptr<sim::SimulatedCableDrives> drives;
  std::vector<hal::CanFrame> reports;  // UPDATE_REPORT frames since the last take_reports()
  std::uint32_t poses_seen = 0;

  UpdateBoard(sim::SimFlash& f, const std::vector<std::uint8_t>& storage_image) : flash(f) {
    storage.assign(storage_image);
    timer.start(1'000'000);
    const hal::CanFilter host_filters[] = {firmware::protocol::kUpdateReportFrames, firmware::protocol::kPoseFrames};
    host_node.set_filters(host_filters, 2);
    boot();
  }

  // Power on (again): a new runtime on what the flash holds.
  void boot() {
    flash.power_on();
    runtime = std::make_unique<firmware::Runtime>(hal, firmware::Geometry::uniform(2, 120.0f, 67.0f));
    runtime->init();
    drives = std::make_unique<sim::SimulatedCableDrives>(bus.node(1), bent_cables(runtime->geometry()), 50.0);
    hal::CanFrame frame;
    while (host_node.receive(frame) == hal::CanStatus::ok) {
    }
  }

  // The image the runtime runs, or an empty vector.
  std::vector<std::uint8_t> active_image() const {
    const int slot = runtime->model_update().active_slot();
    if (slot < 0) {
      const hal::MemoryRegion region = storage.model_region();
      return region.data == nullptr ? std::vector<std::uint8_t>{}
                                    : std::vector<std::uint8_t>(region.data, region.data + region.size_bytes);
    }
    firmware::SlotHeader header;
    if (!firmware::read_slot_header(flash, slot, header)) return {};
    const std::uint8_t* image = flash.read() + firmware::slot_geometry(flash, slot).image_offset();
    return std::vector<std::uint8_t>(image, image + header.image_size);
  }

  void send(const hal::CanFrame& frame) { host_node.send(frame); }
  void send(const std::vector<hal::CanFrame>& frames) {
    for (const hal::CanFrame& frame : frames) host_node.send(frame);
  }

  // One cycle: the drives' cables, the host's frames, the runtime's cycle,
  // what the host hears.
  void cycle(const std::vector<hal::CanFrame>& host_frames = {}) {
    const hal::TimerTick tick = timer.wait_next();
    drives->step(1e-3);
    send(host_frames);
    runtime->run_cycle(tick);
    hal::CanFrame frame;
    while (host_node.receive(frame) == hal::CanStatus::ok) {
      if (firmware::protocol::update_report::kMessage.carries(frame.id)) reports.push_back(frame);
      if (firmware::protocol::pose_position_z::kMessage.carries(frame.id)) poses_seen += 1;
    }
  }

  std::vector<hal::CanFrame> take_reports() {
    std::vector<hal::CanFrame> taken;
    taken.swap(reports);
    return taken;
  }

  std::int64_t now_ms() const { return clock.now_ns() / 1'000'000; }

  // Drives `sender` until it is done, the flash loses power or `limit`
  // cycles pass; returns the cycles run. Up to 4 blocks a cycle.
  int run_sender(UpdateSender& sender, int limit, bool start = true) {
    FrameQueue out;
    if (start) sender.start(out, now_ms());
    int count = 0;
    while (count < limit && sender.outcome() == UpdateSender::Outcome::running && !flash.power_lost()) {
      sender.pump(now_ms(), out, 44);
      cycle(out.take());
      for (const hal::CanFrame& report : take_reports()) sender.on_report(report, now_ms(), out);
      ++count;
    }
    return count;
  }
};

// The last UPDATE_REPORT among `reports`.
inline firmware::protocol::UpdateReport last_report(const std::vector<hal::CanFrame>& reports) {
  firmware::protocol::UpdateReport report;
  if (!reports.empty()) firmware::protocol::decode(reports.back(), report);
  return report;
}

// The REASON of every UPDATE_REPORT among `reports`, in order.
inline std::vector<firmware::protocol::UpdateReason> report_reasons(const std::vector<hal::CanFrame>& reports) {
  std::vector<firmware::protocol::UpdateReason> found;
  for (const hal::CanFrame& frame : reports) {
    firmware::protocol::UpdateReport report;
    if (firmware::protocol::decode(frame, report) == firmware::protocol::DecodeStatus::ok) {
      found.push_back(report.reason);
    }
  }
  return found;
}

inline std::vector<std::uint8_t> update_test_image(int training_points, std::uint32_t seed, int segments = 2,
                                                   double backbone_mm = 0) {
  SyntheticModelOptions options;
  options.training_points = training_points;
  options.seed = seed;
  options.segments = segments;
  training::TrainedModel m = synthetic_trained_model(options);
  for (int k = 0; k < 6; ++k) {
    m.output_mean[k] *= k < 3 ? 0.1 : 0.001;
    m.output_scale[k] *= k < 3 ? 0.1 : 0.001;
  }
  if (backbone_mm > 0) {
    for (int s = 0; s < segments; ++s) m.geometry.segments[s].backbone_length_mm = backbone_mm;
  }
  return exporting::write_image(m);
}

}  // namespace cdcr::test_support
