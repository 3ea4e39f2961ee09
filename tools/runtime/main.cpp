// cdcr-runtime: the firmware's cycle code on the host.
//   --replay: the forward path over recorded cable lengths, as fast as possible.
//   --sim:    the closed loop with simulated drives and robot over the virtual
//             bus, at a fixed rate in lockstep simulated time.
//   --can:    the runtime itself on a SocketCAN interface, in real time, until
//             --seconds have passed or SIGINT/SIGTERM.
// Exit codes as the cdcr command's (cli_errors.hpp).

#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

#include "cli/bus_command.hpp"
#include "cli/cli_errors.hpp"
#include "runtime_modes.hpp"

using namespace cdcr::runtime_host;
using cdcr::cli::kExitInvalidInput;
using cdcr::cli::kExitUsage;

namespace {

// --view, --record and --view-rate (bus_view.hpp), checked after parsing.
struct ViewOptions {
  CLI::Option* view;
  CLI::Option* record;
};

ViewOptions add_view_options(CLI::App& app, ViewChoice& choice) {
  ViewOptions options;
  options.view = app.add_option("--view", choice.port,
                                "with --sim: serve the robot live on this port (Foxglove WebSocket, tools/view; 0: "
                                "any free port); the loop then runs in real time");
  options.record = app.add_option("--record", choice.record_path,
                                  "with --sim or --replay: record the view's channels to this MCAP file");
  app.add_option("--view-rate", choice.scene_rate_hz, "the scene's rate for --view and --record, Hz")
      ->capture_default_str();
  return options;
}

void check_view_options(const ViewOptions& options, const ViewChoice& choice, bool run_sim, bool replay) {
  if (options.view->count() > 0 && !run_sim) throw CLI::ValidationError("--view needs --sim (a bus: cdcr view --can)");
  if (options.view->count() > 0 && !(choice.port >= 0 && choice.port <= 65535)) {
    throw CLI::ValidationError("--view must be a port in [0, 65535]");
  }
  if (options.record->count() > 0 && !run_sim && !replay) throw CLI::ValidationError("--record needs --sim or --replay");
  if (!(choice.scene_rate_hz > 0) || !(choice.scene_rate_hz <= 1000)) {
    throw CLI::ValidationError("--view-rate must be in (0, 1000] Hz");
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The firmware runtime on the host: replay recorded cables or run the simulated closed loop."};
  app.name("cdcr-runtime");
  std::string image_path, replay_path, out_path;
  bool run_sim = false;
  std::string can_interface;
  bool ideal_robot = false;
  bool circle = false;
  double rate_hz = 1000.0, seconds = 2.0, circle_radius_mm = 40.0, circle_speed_mm_s = 50.0;
  app.add_option("--image", image_path, "model image (flash image v2, or v1)");
  std::string flash_dir;
  app.add_option("--flash-dir", flash_dir,
                 "with --can: directory of the file-backed flash that models deployed over CAN are written to");
  auto* replay_option = app.add_option("--replay", replay_path, "cable-length CSV (dataset layout) to replay");
  app.add_option("--out", out_path, "pose CSV written by --replay");
  auto* sim_option = app.add_flag("--sim", run_sim, "close the loop with the simulated robot");
  auto* can_option = app.add_option("--can", can_interface,
                                    "run on this SocketCAN interface in real time (until --seconds or SIGINT/SIGTERM)");
  bool spin = false;
  auto* spin_option = app.add_flag("--spin", spin,
                                   "with --can: spin to each release instead of sleeping (a core reserved for the "
                                   "runtime: no wake-up on a cold core, the whole core used)");
  app.add_option("--rate", rate_hz, "cycle rate for --sim, Hz")->capture_default_str();
  app.add_option("--seconds", seconds, "simulated duration for --sim")->capture_default_str();
  app.add_flag("--ideal-robot", ideal_robot, "--sim with every simulated error source off (the nominal model)");
  bool hysteresis = false;
  app.add_flag("--hysteresis", hysteresis,
               "--sim with the cables' friction hysteresis (as cdcr simulate --hysteresis): the tip depends on the "
               "path of the drives. The robot first homes (then HOMING is sent), and each target is approached from "
               "two sides (four half-second legs per target)");
  app.add_flag("--circle", circle,
               "--sim following a streamed circle (a TRACKING pose target every cycle), once round");
  app.add_option("--circle-radius", circle_radius_mm, "--circle radius, mm")->capture_default_str();
  app.add_option("--circle-speed", circle_speed_mm_s, "--circle tip speed, mm/s")->capture_default_str();
  BusChoice bus;
  cdcr::cli::add_bus_layout_options(app, bus.layout,
                                    "the bus's bit rate, bit/s: the bus budget (cdcr bus) is printed and a "
                                    "configuration above its limit refused; --sim times its bus at this rate (0: an "
                                    "untimed bus, frames delivered at once)",
                                    false);
  app.add_flag("--drives-bus", bus.layout.drives_bus, "with --sim: the drives on a simulated bus of their own");
  std::string drives_interface;
  auto* drives_can_option =
      app.add_option("--drives-can", drives_interface,
                     "with --can: the drives' own SocketCAN interface (CABLE_FEEDBACK in, the setpoints out)");
  cdcr::cli::add_publish_rate_options(app, bus.rates);
  std::string id_base_text;
  cdcr::cli::add_id_base_option(app, id_base_text);
  std::string drives_kind = "protocol";
  auto* drives_option =
      app.add_option("--drives", drives_kind,
                     "with --can: the drives' kind: protocol (CABLE_FEEDBACK / CABLE_SETPOINT) or cia402 (CiA 402 "
                     "drives over CANopen, on the buses of --drives-config; SIGUSR1 recovers them after a fault)")
          ->check(CLI::IsMember({"protocol", "cia402"}))
          ->capture_default_str();
  auto* drives_config_option =
      app.add_option("--drives-config", bus.cia402_config, "with --drives cia402: the drives' configuration (JSON)");
  auto* streaming_option = app.add_flag("--streaming", bus.streaming,
                                        "with --can and --bitrate: plan the budget for a target streamed every cycle");
  const ViewOptions view_options = add_view_options(app, bus.view);
  replay_option->excludes(sim_option);
  can_option->excludes(sim_option)->excludes(replay_option);
  try {
    app.parse(argc, argv);
    if (!run_sim && replay_path.empty() && can_interface.empty()) {
      throw CLI::ValidationError("one of --replay, --sim or --can is required");
    }
    if (circle && !run_sim) throw CLI::ValidationError("--circle needs --sim");
    check_view_options(view_options, bus.view, run_sim, !replay_path.empty());
    if (hysteresis && !run_sim) throw CLI::ValidationError("--hysteresis needs --sim");
    if (!flash_dir.empty() && can_interface.empty()) throw CLI::ValidationError("--flash-dir needs --can");
    if (streaming_option->count() > 0 && can_interface.empty()) {
      throw CLI::ValidationError("--streaming needs --can (--sim --circle streams)");
    }
    bus.id_base = cdcr::cli::parse_id_base(id_base_text);
    if (drives_can_option->count() > 0 && can_interface.empty()) throw CLI::ValidationError("--drives-can needs --can");
    if (bus.layout.drives_bus && !run_sim) throw CLI::ValidationError("--drives-bus needs --sim (--can: --drives-can)");
    if (drives_option->count() > 0 && can_interface.empty()) throw CLI::ValidationError("--drives needs --can");
    if ((drives_kind == "cia402") != (drives_config_option->count() > 0))
      throw CLI::ValidationError("--drives cia402 and --drives-config go together");
    if (drives_kind == "cia402" && !drives_interface.empty())
      throw CLI::ValidationError("--drives cia402 takes its buses from --drives-config, not --drives-can");
    if (!drives_interface.empty()) {
      bus.layout.drives_bus = true;
      bus.layout.drives_option = "--drives-can";
    }
    cdcr::cli::resolve_bus_layout(bus.layout, true);
    cdcr::cli::validate_publish_rates(bus.rates);
    if (spin_option->count() > 0 && can_interface.empty()) throw CLI::ValidationError("--spin needs --can");
    if (!replay_path.empty() && (image_path.empty() || out_path.empty())) {
      throw CLI::ValidationError("--replay needs --image and --out");
    }
  } catch (const cdcr::cli::InputError& e) {
    std::fprintf(stderr, "cdcr-runtime: error: %s\n", e.what());
    return kExitUsage;
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "cdcr-runtime: error: %s\n", e.what());
    return kExitUsage;
  }
  try {
    if (!can_interface.empty()) {
      return run_on_socketcan(image_path, can_interface, drives_interface, rate_hz, app.count("--seconds") > 0 ? seconds : 0.0,
                              flash_dir, spin, bus);
    }
    const SimulatedRobotChoice robot{ideal_robot, hysteresis};
    if (run_sim && circle) {
      return follow_circle(image_path, rate_hz, circle_radius_mm, circle_speed_mm_s, robot, bus);
    }
    return run_sim ? simulate(image_path, rate_hz, seconds, robot, bus) : replay(image_path, replay_path, out_path, bus.view);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "cdcr-runtime: error: %s\n", e.what());
    return kExitUsage;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cdcr-runtime: error: %s\n", e.what());
    return kExitInvalidInput;
  }
}
