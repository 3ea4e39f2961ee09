#pragma once
// cdcr-runtime's three ways of running the firmware's cycle code on the host,
// one file each; main.cpp picks one from the command line. Each throws
// std::invalid_argument for an option value out of range (a usage error) and
// cli::InputError for input it cannot use (cli_errors.hpp).

#include <cstdint>
#include <string>
#include <vector>

#include <cdcr/firmware/protocol/messages.hpp>
#include <cdcr/firmware/publish_rates.hpp>

#include "bus_view.hpp"
#include "cli/bus_command.hpp"

namespace cdcr::runtime_host {

// The bus and the runtime's publish rates (firmware/publish_rates.hpp). With
// a bit rate the configuration's bus budget (cdcr bus) is printed before the
// run and a configuration above the limit is refused; --sim then times its
// bus at that rate (0: the untimed, infinitely fast bus) and reports what it
// carried.
//
// The layout (cli/bus_command.hpp): the format of each bus, and a second bus
// for the drives (--sim --drives-bus; --can with --drives-can IFACE).
struct BusChoice {
  BusChoice() { layout.bus.bitrate = 0; }
  // Where the protocol's identifiers start (firmware/protocol/messages.hpp):
  // the runtime, the simulated drives and host all send and read there, on
  // either bus.
  std::uint32_t id_base = firmware::protocol::kDefaultIdBase;
  cli::BusLayout layout;
  firmware::PublishRates rates{};
  bool streaming = false;  // --can: plan for a target streamed every cycle (--circle streams)
  // --can --drives cia402: the CiA 402 drives' configuration file
  // (cli/drives_config.hpp); empty: the protocol's drives.
  std::string cia402_config;
  // Filled from it for the budget: the drives on each bus, their heartbeat.
  std::vector<int> cia402_per_bus;
  int cia402_heartbeat_ms = 50;
  // A listener on the bus: the view served live and/or recorded (--sim
  // --view, --record; bus_view.hpp).
  ViewChoice view;
};

// Prints the budget of every bus of `segments` at rate_hz on `bus` and throws
// cli::InputError, one line, when it is above the limit; nothing without a
// bit rate.
void check_bus_budget(int segments, double rate_hz, bool streaming, const BusChoice& bus);

// --replay: the forward path over recorded cable lengths, as fast as
// possible, into a pose CSV; with view.record_path also the view's
// recording of the rows, sent as the drives would send them (CABLE_FEEDBACK
// at each row's time, HOMING at each session's start for an image that
// tracks the cables' hysteresis).
int replay(const std::string& image_path, const std::string& cables_path, const std::string& out_path,
           const ViewChoice& view = {});

// The simulated robot of --sim: --ideal-robot turns every error source off;
// --hysteresis turns the cables' friction hysteresis on (source 7 of
// tools/sim/simulator_config.hpp, as `cdcr simulate --hysteresis`): the
// friction follows every change of the drives' lengths, so the tip depends
// on the path. With it the loop starts as a real robot does: the homing move
// (model::homing_waypoints), then a HOMING frame.
struct SimulatedRobotChoice {
  bool ideal_robot = false;
  bool hysteresis = false;
};

// --sim: the closed loop with simulated drives and robot over the virtual
// bus, at a fixed rate in lockstep simulated time; the six demo targets
// (--seconds 3), with --hysteresis each approached from two sides.
int simulate(const std::string& image_path, double rate_hz, double seconds, const SimulatedRobotChoice& robot,
             const BusChoice& bus);
// --sim --circle: the same loop following a streamed circle.
int follow_circle(const std::string& image_path, double rate_hz, double radius_mm, double speed_mm_s,
                  const SimulatedRobotChoice& robot, const BusChoice& bus);

// --can: the runtime itself on a SocketCAN interface, in real time, until
// `seconds` have passed (0: no limit) or SIGINT/SIGTERM.
// drives_interface: the drives' own bus (empty: they share interface_name).
int run_on_socketcan(const std::string& image_path, const std::string& interface_name,
                     const std::string& drives_interface, double rate_hz, double seconds, const std::string& flash_dir,
                     bool spin, const BusChoice& bus);

// The cycle rate every mode accepts: (0, 100000] Hz.
void require_rate(double rate_hz);

}  // namespace cdcr::runtime_host
