#pragma once
// cdcr bus: the CAN bus budget of a configuration (firmware/protocol/
// bus_budget.hpp) before anything runs: every message's frames a second,
// its worst-case bits and its share of the bus, the bus's worst-case load
// and the load without a stuff bit. A configuration above the limit
// (firmware::kMaxBusLoad) prints its table and fails with one line that
// gives the load and names the ways to fit. cdcr-runtime checks its own
// configuration with the same code before it starts.

#include <cstdint>
#include <string>
#include <vector>

#include <cdcr/firmware/canopen/bus_budget.hpp>
#include <cdcr/firmware/protocol/bus_budget.hpp>
#include <cdcr/firmware/publish_rates.hpp>
#include <cdcr/hal/can_timing.hpp>

#include "command_output.hpp"

namespace CLI {
class App;
}

namespace cdcr::cli {

// One bus: its format (classical, fd, fd-brs) and bit rates, bit/s.
struct BusLine {
  hal::CanFormat format = hal::CanFormat::classical;
  std::uint32_t bitrate = 1000000;
  std::uint32_t data_bitrate = 0;  // the data phase's, fd-brs only
};

// The buses of a configuration: one, or the host's and one of the drives'
// own. The drives' bus takes the host's format and rates unless given.
struct BusLayout {
  BusLine bus;
  std::string format_text = "classical";
  bool drives_bus = false;
  BusLine drives{hal::CanFormat::classical, 0, 0};  // a rate of 0: the host bus's
  std::string drives_format_text;  // empty: the host bus's
  // How the command names a second bus, for the refusal's ways to fit.
  std::string drives_option = "--drives-bus";
};

struct BusOptions {
  int segments = 4;
  double rate_hz = 1000.0;
  bool streaming = false;
  firmware::PublishRates rates{};
  BusLayout layout;
  bool json = false;
  // CiA 402 drives over CANopen instead of the protocol's: this many, as
  // evenly as they go over cia402_buses buses of their own (the host's
  // bus's format and rate), each with its heartbeat every heartbeat_ms.
  int cia402_drives = 0;
  int cia402_buses = 1;
  int heartbeat_ms = 50;
  // The drives on each bus as a configuration has them (cdcr-runtime
  // --drives-config); empty: as evenly as they go.
  std::vector<int> cia402_per_bus;
};

// One bus's budget, and the bus.
struct NamedBudget {
  std::string name;  // "host", "drives"; empty on one bus
  BusLine line;
  firmware::protocol::BusBudget budget;
};

// --pose-every, --uncertainty-every and --status-every, for cdcr bus and
// cdcr-runtime alike.
void add_publish_rate_options(CLI::App& command, firmware::PublishRates& rates);
// --bitrate (bit/s, a bus's nominal rate), --can-format, --data-bitrate,
// and for the drives' own bus --drives-bitrate, --drives-can-format and
// --drives-data-bitrate (and, with add_drives_flag, --drives-bus).
void add_bus_layout_options(CLI::App& command, BusLayout& layout, const std::string& bitrate_what,
                            bool add_drives_flag);
// Parses the formats and fills in the drives' bus from the host's; throws
// InputError for a value out of range (a bit rate of 0 is let through
// where allow_untimed: no budget, an untimed simulated bus).
void resolve_bus_layout(BusLayout& layout, bool allow_untimed);
// "classical CAN at 1 Mbit/s", "CAN FD at 1 Mbit/s, data at 5 Mbit/s".
std::string bus_line_text(const BusLine& line);
firmware::protocol::BusSetup bus_setup(const BusLine& line, firmware::protocol::BusRole role);

// --id-base (decimal or 0x-hexadecimal): where the protocol's identifiers
// start (firmware/protocol/messages.hpp), for cdcr deploy and cdcr-runtime.
void add_id_base_option(CLI::App& command, std::string& text);
// The base in `text`, kDefaultIdBase for ""; throws InputError for a base
// the protocol cannot take.
std::uint32_t parse_id_base(const std::string& text);

// Throw InputError for values out of range (resolves the layout).
void validate_bus_options(BusOptions& options);
void validate_publish_rates(const firmware::PublishRates& rates);
// Every bus's budget, the host's first (a resolved layout).
std::vector<NamedBudget> bus_budgets_of(const BusOptions& options);
// With CiA 402 drives (options.cia402_drives > 0): the host's, then each
// CANopen bus's.
std::vector<NamedBudget> cia402_budgets_of(const BusOptions& options);
// The budgets as tables, and their verdicts.
std::string format_bus_budgets(const std::vector<NamedBudget>& budgets, const BusOptions& options);
// One line when a bus's budget is above the limit: its load, the limit and
// the ways to fit; empty when every bus fits.
std::string bus_budget_refusal(const std::vector<NamedBudget>& budgets, const BusOptions& options);

void register_bus_command(CLI::App& app, CommandOutput& output);
CommandOutput run_bus(BusOptions options);

}  // namespace cdcr::cli
