#include "view_command.hpp"

#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <cdcr/firmware/protocol/messages.hpp>
#include <cdcr/linux/socketcan_bus.hpp>

#include "bus_command.hpp"
#include "cli_errors.hpp"
#include "export/binary_file.hpp"
#include "view/view_session.hpp"

namespace cdcr::cli {

namespace {

volatile std::sig_atomic_t stop_requested = 0;
void request_stop(int) { stop_requested = 1; }

}  // namespace

void register_view_command(CLI::App& app, CommandOutput& output) {
  auto options = std::make_shared<ViewCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "view", "Serve the robot on the bus live to Foxglove (WebSocket) and record it to MCAP; never sends a frame");
  command->add_option("--can", options->can_interface, "SocketCAN interface of the host's bus")->required();
  command->add_option("--drives-can", options->drives_can_interface,
                      "the drives' own SocketCAN interface, where they have one");
  command->add_flag("--fd", options->fd, "the buses carry CAN FD frames");
  command->add_option("--image", options->image_path, "the runtime's model image")->required()->type_name("FILE");
  command->add_option("--port", options->port, "WebSocket port (0: a free one)")->capture_default_str();
  command->add_option("--record", options->record_path, "also record to this MCAP file")->type_name("FILE.mcap");
  command->add_option("--seconds", options->seconds, "stop after this long (0: at SIGINT or SIGTERM)")
      ->capture_default_str();
  command->add_option("--view-rate", options->scene_rate_hz, "the scene's rate, Hz")->capture_default_str();
  add_id_base_option(*command, options->id_base);
  command->callback([options, &output] {
    if (!(options->port >= 0 && options->port <= 65535)) throw UsageError("--port must be in [0, 65535]");
    if (!(options->seconds >= 0)) throw UsageError("--seconds must not be negative");
    if (!(options->scene_rate_hz > 0) || !(options->scene_rate_hz <= 1000)) {
      throw UsageError("--view-rate must be in (0, 1000] Hz");
    }
    output = run_view(*options);
  });
}

CommandOutput run_view(const ViewCommandOptions& options) {
  view::ViewOptions view_options;
  view_options.scene_rate_hz = options.scene_rate_hz;
  view_options.id_offset = firmware::protocol::id_offset(parse_id_base(options.id_base));
  std::vector<std::unique_ptr<linux_host::SocketCanBus>> buses;
  for (const std::string& name : {options.can_interface, options.drives_can_interface}) {
    if (name.empty()) continue;
    auto bus = std::make_unique<linux_host::SocketCanBus>();
    std::string error;
    if (!bus->open(name, error, options.fd)) throw InputError(error);
    bus->set_filters(nullptr, 0);  // every frame
    buses.push_back(std::move(bus));
  }
  std::vector<std::uint8_t> image;
  try {
    image = exporting::read_binary_file(options.image_path);
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  std::unique_ptr<view::ViewSession> session;
  try {
    session = std::make_unique<view::ViewSession>(image, view_options,
                                                  view::ViewOutputs{options.port, options.record_path, "cdcr view"});
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
  view::RobotView& robot_view = session->view();
  if (!robot_view.note().empty()) std::fprintf(stderr, "view: note: %s\n", robot_view.note().c_str());
  std::fprintf(stderr, "view: ws://127.0.0.1:%u (Foxglove WebSocket) from %s%s%s; Ctrl-C stops\n",
               unsigned(session->port()), options.can_interface.c_str(),
               options.drives_can_interface.empty() ? "" : " and ", options.drives_can_interface.c_str());
  std::fflush(stderr);

  struct sigaction action {};
  action.sa_handler = request_stop;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  const auto start = std::chrono::steady_clock::now();
  while (stop_requested == 0 &&
         (options.seconds <= 0 ||
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < options.seconds)) {
    bool any = false;
    hal::CanFrame frame;
    for (auto& bus : buses) {
      while (bus->receive(frame) == hal::CanStatus::ok) {
        robot_view.on_frame(frame, view::wall_clock_ns());
        any = true;
      }
    }
    if (!any) std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  CommandOutput output;
  output.text = fmt::format("view: {} frames seen ({} malformed), {} scenes\n", robot_view.frames(),
                            robot_view.malformed_frames(), robot_view.scenes());
  session->close_recording();
  if (const std::string report = session->recording_report(); !report.empty()) output.text += report + "\n";
  return output;
}

}  // namespace cdcr::cli
