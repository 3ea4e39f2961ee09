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

#include <cdcr/firmware/protocol/bus_budget.hpp>
#include <cdcr/firmware/publish_rates.hpp>

#include "command_output.hpp"

namespace CLI {
class App;
}

namespace cdcr::cli {

struct BusOptions {
  int segments = 4;
  double rate_hz = 1000.0;
  bool streaming = false;
  firmware::PublishRates rates{};
  std::uint32_t bitrate = 1000000;  // bit/s
  bool json = false;
};

// --pose-every, --uncertainty-every and --status-every, for cdcr bus and
// cdcr-runtime alike.
void add_publish_rate_options(CLI::App& command, firmware::PublishRates& rates);
// --bitrate (bit/s, a bus's nominal rate).
void add_bitrate_option(CLI::App& command, std::uint32_t& bitrate, const std::string& what);

// --id-base (decimal or 0x-hexadecimal): where the protocol's identifiers
// start (firmware/protocol/messages.hpp), for cdcr deploy and cdcr-runtime.
void add_id_base_option(CLI::App& command, std::string& text);
// The base in `text`, kDefaultIdBase for ""; throws InputError for a base
// the protocol cannot take.
std::uint32_t parse_id_base(const std::string& text);

// Throw InputError for values out of range.
void validate_bus_options(const BusOptions& options);
void validate_publish_rates(const firmware::PublishRates& rates);
firmware::protocol::BusBudget bus_budget_of(const BusOptions& options);
// The budget as a table, and its verdict.
std::string format_bus_budget(const firmware::protocol::BusBudget& budget, const BusOptions& options);
// One line when the budget is above the limit: its load, the limit and the
// ways to fit; empty when it fits.
std::string bus_budget_refusal(const firmware::protocol::BusBudget& budget, const BusOptions& options);

void register_bus_command(CLI::App& app, CommandOutput& output);
CommandOutput run_bus(const BusOptions& options);

}  // namespace cdcr::cli
