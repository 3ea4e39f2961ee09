#include "deploy_command.hpp"

#include <chrono>
#include <cstdio>
#include <deque>
#include <memory>
#include <thread>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <cdcr/firmware/capacity.hpp>
#include <cdcr/firmware/update/update_sender.hpp>
#include <cdcr/hal/shifted_can_bus.hpp>

#include "bus_command.hpp"
#include "cdcr/linux/socketcan_bus.hpp"
#include "cli_errors.hpp"
#include "export/binary_file.hpp"

namespace cdcr::cli {

namespace {

namespace protocol = firmware::protocol;

std::string reason_text(protocol::UpdateReason reason) {
  switch (reason) {
    case protocol::UpdateReason::wrong_geometry: return "the image was trained for another robot geometry";
    case protocol::UpdateReason::wrong_segment_count: return "the image has another segment count than the robot";
    case protocol::UpdateReason::unsupported_version: return "the runtime does not read this image format version";
    case protocol::UpdateReason::too_large: return "the image is too large for the runtime's flash slot";
    case protocol::UpdateReason::busy: return "another transfer is in progress on the runtime";
    case protocol::UpdateReason::image_invalid: return "the image does not validate (corrupted or inconsistent)";
    case protocol::UpdateReason::digest_mismatch: return "the received image's SHA-256 does not match";
    case protocol::UpdateReason::timeout: return "the runtime timed the transfer out";
    case protocol::UpdateReason::no_rollback_image: return "no valid image in the other slot to roll back to";
    case protocol::UpdateReason::flash_failed: return "the runtime has no usable flash (run it with --flash-dir)";
    default: break;
  }
  for (const protocol::ValueName& name : protocol::values::kUpdateReason) {
    if (name.value == static_cast<std::uint32_t>(reason)) return name.name;
  }
  return "unknown reason";
}

const char* slot_name(std::uint8_t slot) { return slot == 1 ? "A" : slot == 2 ? "B" : "model storage"; }

std::int64_t now_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// The SocketCAN bus behind a queue: a frame the socket has no room for
// waits for the next flush() instead of being dropped.
class Link final : public hal::CanBus {
 public:
  Link(const std::string& interface_name, std::uint32_t id_base) : bus_(socket_, protocol::id_offset(id_base)) {
    std::string error;
    if (!socket_.open(interface_name, error)) throw InputError("CAN interface " + interface_name + ": " + error);
    const hal::CanFilter filters[] = {protocol::kUpdateReportFrames};
    bus_.set_filters(filters, 1);
  }
  // Sends what the queue takes; the rest waits for the next call.
  void flush() {
    while (!pending_.empty() && bus_.send(pending_.front()) == hal::CanStatus::ok) pending_.pop_front();
  }
  bool idle() const { return pending_.empty(); }
  bool receive(protocol::UpdateReport& report, hal::CanFrame& frame) {
    while (bus_.receive(frame) == hal::CanStatus::ok) {
      if (protocol::decode(frame, report) == protocol::DecodeStatus::ok) return true;
    }
    return false;
  }

  hal::CanStatus send(const hal::CanFrame& frame) override {
    pending_.push_back(frame);
    return hal::CanStatus::ok;
  }
  hal::CanStatus receive(hal::CanFrame& frame) override { return bus_.receive(frame); }
  bool set_filters(const hal::CanFilter* filters, std::size_t count) override {
    return bus_.set_filters(filters, count);
  }
  hal::CanErrorCounters error_counters() const override { return bus_.error_counters(); }

 private:
  linux_host::SocketCanBus socket_;
  hal::ShiftedCanBus bus_;  // the runtime's identifiers, wherever its base puts them
  std::deque<hal::CanFrame> pending_;
};

void draw_progress(std::uint32_t done, std::uint32_t total) {
  constexpr int kWidth = 40;
  const int filled = total == 0 ? kWidth : static_cast<int>(std::uint64_t(kWidth) * done / total);
  std::fprintf(stderr, "\r[%s%s] %3u%% %u/%u blocks", std::string(filled, '#').c_str(),
               std::string(kWidth - filled, '.').c_str(), total == 0 ? 100u : unsigned(100ull * done / total), done,
               total);
  std::fflush(stderr);
}

// One command, and the first report about it.
protocol::UpdateReport command(Link& link, protocol::UpdateCommand which, double timeout_s) {
  hal::CanFrame frame;
  protocol::encode(protocol::UpdateCommandFrame{which, 0, 0}, frame);
  link.send(frame);
  const std::int64_t deadline = now_ms() + static_cast<std::int64_t>(timeout_s * 1000);
  protocol::UpdateReport report;
  while (now_ms() < deadline) {
    link.flush();
    if (link.receive(report, frame)) return report;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  throw InputError("no answer from the runtime (is cdcr-runtime running on this bus?)");
}

}  // namespace

CommandOutput run_deploy(const DeployCommandOptions& options) {
  CommandOutput output;
  Link link(options.can_interface, parse_id_base(options.id_base));
  if (options.status) {
    const protocol::UpdateReport report = command(link, protocol::UpdateCommand::status, 2.0);
    output.text = fmt::format("state {}, active slot {} (sequence {}), {} blocks in flash, transfer {:04x}{}\n",
                              protocol::values::kUpdateState[static_cast<int>(report.state)].name,
                              slot_name(report.active_slot), report.active_sequence, report.next_block,
                              report.transfer_id,
                              report.reason == protocol::UpdateReason::none ? "" : ", " + reason_text(report.reason));
    return output;
  }
  if (options.rollback) {
    protocol::UpdateReport report = command(link, protocol::UpdateCommand::rollback, 2.0);
    const std::int64_t deadline = now_ms() + static_cast<std::int64_t>(options.timeout_s * 1000);
    hal::CanFrame frame;
    while (report.reason == protocol::UpdateReason::none && report.state != protocol::UpdateState::committed) {
      if (now_ms() > deadline) throw InputError("the runtime did not finish the rollback");
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      link.receive(report, frame);
    }
    if (report.reason != protocol::UpdateReason::none) {
      throw InputError("the runtime refused the rollback: " + reason_text(report.reason));
    }
    output.text = fmt::format("rolled back: slot {} (sequence {}) runs\n", slot_name(report.active_slot),
                              report.active_sequence);
    return output;
  }

  std::vector<std::uint8_t> image = exporting::read_binary_file(options.image_path);
  if (image.empty()) throw InputError(options.image_path + ": empty file");
  if (image.size() > 0xFFFFFF) throw InputError(options.image_path + ": larger than a transfer can carry (16 MiB)");
  firmware::UpdateSender sender(image.data(), static_cast<std::uint32_t>(image.size()));
  sender.start(link, now_ms());
  std::int64_t last_progress_ms = now_ms();
  std::uint32_t last_acknowledged = 0;
  const std::int64_t started_ms = now_ms();
  while (sender.outcome() == firmware::UpdateSender::Outcome::running) {
    sender.receive_reports(link, now_ms());
    // A window's worth of blocks, less one frame: room for a COMMIT.
    if (link.idle()) sender.pump(now_ms(), link, firmware::UpdateSender::kFramesPerBlock * firmware::kUpdateWindowBlocks - 1);
    link.flush();
    if (sender.acknowledged_blocks() != last_acknowledged) {
      last_acknowledged = sender.acknowledged_blocks();
      last_progress_ms = now_ms();
      if (!options.quiet) draw_progress(last_acknowledged, sender.total_blocks());
    }
    if (now_ms() - last_progress_ms > static_cast<std::int64_t>(options.timeout_s * 1000)) {
      if (!options.quiet) std::fprintf(stderr, "\n");
      throw InputError(fmt::format("no progress for {} s: transfer stopped at block {} of {} (run again to resume)",
                                   options.timeout_s, last_acknowledged, sender.total_blocks()));
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  if (!options.quiet) std::fprintf(stderr, "\n");
  if (sender.outcome() == firmware::UpdateSender::Outcome::refused) {
    throw InputError("the runtime refused " + options.image_path + ": " + reason_text(sender.refusal()));
  }
  const double seconds = double(now_ms() - started_ms) * 1e-3;
  output.text = fmt::format("deployed {}: {} blocks, {} frames in {:.2f} s; the new model runs\n", options.image_path,
                            sender.total_blocks(), sender.frames_sent(), seconds);
  return output;
}

void register_deploy_command(CLI::App& app, CommandOutput& output) {
  auto options = std::make_shared<DeployCommandOptions>();
  CLI::App* command =
      app.add_subcommand("deploy", "Send a model image to the runtime over CAN (A/B flash slots, resumable)");
  command->add_option("--can", options->can_interface, "SocketCAN interface")->required();
  auto* image = command->add_option("--image", options->image_path, "Model image to deploy")->type_name("FILE");
  auto* status = command->add_flag("--status", options->status, "Print the runtime's update state and active slot");
  auto* rollback = command->add_flag("--rollback", options->rollback, "Make the other slot's model active again");
  command->add_option("--timeout", options->timeout_s, "Give up after this many seconds without progress")
      ->capture_default_str();
  command->add_flag("--quiet", options->quiet, "No progress bar");
  add_id_base_option(*command, options->id_base);
  image->excludes(status)->excludes(rollback);
  status->excludes(rollback);
  command->callback([options, command, &output] {
    if (options->image_path.empty() && !options->status && !options->rollback) {
      throw UsageError("deploy needs --image, --status or --rollback");
    }
    if (!(options->timeout_s > 0)) throw UsageError("--timeout must be positive");
    (void)command;
    output = run_deploy(*options);
  });
}

}  // namespace cdcr::cli
