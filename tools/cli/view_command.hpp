#pragma once
// cdcr view: the robot as its bus shows it, served live to Foxglove or
// Lichtblick over the Foxglove WebSocket protocol and optionally recorded to
// MCAP (tools/view). It listens like any other node and never sends a frame.

#include <string>

#include "command_output.hpp"

namespace CLI {
class App;
}

namespace cdcr::cli {

struct ViewCommandOptions {
  std::string can_interface;
  std::string drives_can_interface;  // the drives' own bus, if they have one
  bool fd = false;                   // the buses carry CAN FD frames
  std::string image_path;
  int port = 8765;  // 0: a free port, printed
  std::string record_path;
  std::string id_base;  // "": the protocol's default
  double seconds = 0;   // 0: until SIGINT or SIGTERM
  double scene_rate_hz = 30;
};

void register_view_command(CLI::App& app, CommandOutput& output);

CommandOutput run_view(const ViewCommandOptions& options);

}  // namespace cdcr::cli
