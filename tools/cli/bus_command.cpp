#include "bus_command.hpp"

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <utility>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_errors.hpp"
#include "json_output.hpp"

namespace cdcr::cli {

namespace protocol = firmware::protocol;

void add_publish_rate_options(CLI::App& command, firmware::PublishRates& rates) {
  command.add_option("--pose-every", rates.pose_every, "Cycles between poses (POSE_* frames)")->capture_default_str();
  command
      .add_option("--uncertainty-every", rates.uncertainty_every,
                  "Cycles between the starts of pose variances (POSE_UNCERTAINTY goes out as each ends)")
      ->capture_default_str();
  command.add_option("--status-every", rates.status_every, "Cycles between STATUS and STATS")->capture_default_str();
}

void add_bus_layout_options(CLI::App& command, BusLayout& layout, const std::string& bitrate_what,
                            bool add_drives_flag) {
  command.add_option("--bitrate", layout.bus.bitrate, bitrate_what)->capture_default_str();
  command
      .add_option("--can-format", layout.format_text,
                  "classical, fd (CAN FD at the bit rate) or fd-brs (CAN FD, the data phase at --data-bitrate): "
                  "on an FD bus the pose and its radii, a target and four segments' setpoints go one frame each")
      ->capture_default_str();
  command.add_option("--data-bitrate", layout.bus.data_bitrate, "With --can-format fd-brs: the data phase's bit rate");
  if (add_drives_flag) {
    command.add_flag("--drives-bus", layout.drives_bus,
                     "The drives on a bus of their own (CABLE_FEEDBACK and the setpoints), the host on the other");
  }
  command.add_option("--drives-bitrate", layout.drives.bitrate, "The drives' bus's bit rate (default: --bitrate's)");
  command.add_option("--drives-can-format", layout.drives_format_text,
                     "The drives' bus's format (default: --can-format's)");
  command.add_option("--drives-data-bitrate", layout.drives.data_bitrate,
                     "The drives' bus's data bit rate (default: --data-bitrate's)");
}

namespace {

hal::CanFormat parse_format(const std::string& text, const std::string& option) {
  if (text == "classical") return hal::CanFormat::classical;
  if (text == "fd") return hal::CanFormat::fd;
  if (text == "fd-brs") return hal::CanFormat::fd_bit_rate_switch;
  throw InputError(fmt::format("{} must be classical, fd or fd-brs, got '{}'", option, text));
}

void check_line(const BusLine& line, const std::string& prefix, bool allow_untimed) {
  const bool fd = line.format != hal::CanFormat::classical;
  if (!(allow_untimed && line.bitrate == 0) && (line.bitrate < 10000 || line.bitrate > 1000000)) {
    throw InputError(fmt::format("--{}bitrate must be 10000 to 1000000 bit/s ({}), got {}", prefix,
                                 fd ? "CAN FD's arbitration rate" : "classical CAN", line.bitrate));
  }
  if (line.format != hal::CanFormat::fd_bit_rate_switch) {
    if (line.data_bitrate != 0) {
      throw InputError(fmt::format("--{}data-bitrate is for --{}can-format fd-brs", prefix, prefix));
    }
    return;
  }
  if (line.bitrate == 0 && line.data_bitrate == 0) return;  // untimed
  if (line.data_bitrate == 0) {
    throw InputError(fmt::format("--{}can-format fd-brs needs --{}data-bitrate", prefix, prefix));
  }
  if (line.data_bitrate <= line.bitrate || line.data_bitrate > 8000000) {
    throw InputError(fmt::format("--{}data-bitrate must be above --{}bitrate and at most 8000000 bit/s with fd-brs, got {}",
                                 prefix, prefix, line.data_bitrate));
  }
}

}  // namespace

void resolve_bus_layout(BusLayout& layout, bool allow_untimed) {
  layout.bus.format = parse_format(layout.format_text, "--can-format");
  const bool drives_given = layout.drives.bitrate != 0 || layout.drives.data_bitrate != 0 ||
                            !layout.drives_format_text.empty();
  if (drives_given && !layout.drives_bus) {
    throw InputError(fmt::format("--drives-bitrate, --drives-can-format and --drives-data-bitrate need {}",
                                 layout.drives_option));
  }
  check_line(layout.bus, "", allow_untimed);
  if (!layout.drives_bus) return;
  layout.drives.format = layout.drives_format_text.empty()
                             ? layout.bus.format
                             : parse_format(layout.drives_format_text, "--drives-can-format");
  if (layout.drives.bitrate == 0) layout.drives.bitrate = layout.bus.bitrate;
  if (layout.drives.data_bitrate == 0 && layout.drives.format == hal::CanFormat::fd_bit_rate_switch) {
    layout.drives.data_bitrate = layout.bus.data_bitrate;
  }
  check_line(layout.drives, "drives-", allow_untimed);
}

protocol::BusSetup bus_setup(const BusLine& line, protocol::BusRole role) {
  return {line.format, {line.bitrate, line.data_bitrate}, role};
}

void add_id_base_option(CLI::App& command, std::string& text) {
  command.add_option("--id-base", text,
                     "Where the protocol's identifiers start: a multiple of 8 up to 0x780 (default 0x100), for a bus "
                     "shared with other traffic (CANopen's 0x100 is TIME)");
}

std::uint32_t parse_id_base(const std::string& text) {
  if (text.empty()) return protocol::kDefaultIdBase;
  char* end = nullptr;
  const unsigned long base = std::strtoul(text.c_str(), &end, 0);
  if (end == text.c_str() || *end != '\0' || text[0] == '-' || base > hal::kMaxStandardId ||
      !protocol::is_valid_id_base(static_cast<std::uint32_t>(base))) {
    throw InputError("--id-base must be a multiple of 8 from 0 to 0x780, got '" + text + "'");
  }
  return static_cast<std::uint32_t>(base);
}

void validate_bus_options(BusOptions& options) {
  if (options.segments < 1 || options.segments > firmware::kMaxSegments) {
    throw InputError(fmt::format("--segments must be 1 to {}, got {}", firmware::kMaxSegments, options.segments));
  }
  if (!(options.rate_hz > 0.0 && options.rate_hz <= 100000.0)) {
    throw InputError(fmt::format("--rate must be in (0, 100000] Hz, got {}", options.rate_hz));
  }
  resolve_bus_layout(options.layout, false);
  validate_publish_rates(options.rates);
  if (options.cia402_drives < 0 || options.cia402_drives > firmware::kMaxDrives) {
    throw InputError(fmt::format("--cia402 must be 0 to {} drives, got {}", firmware::kMaxDrives,
                                 options.cia402_drives));
  }
  if (options.cia402_buses < 1 || options.cia402_buses > firmware::kMaxDriveBuses) {
    throw InputError(fmt::format("--cia402-buses must be 1 to {}, got {}", firmware::kMaxDriveBuses,
                                 options.cia402_buses));
  }
  if (options.heartbeat_ms < 1 || options.heartbeat_ms > 65535) {
    throw InputError(fmt::format("--heartbeat-ms must be 1 to 65535, got {}", options.heartbeat_ms));
  }
  if (options.cia402_drives > 0 && options.layout.drives_bus) {
    throw InputError("--cia402 puts the drives on CANopen buses of their own: --drives-bus does not apply");
  }
}

void validate_publish_rates(const firmware::PublishRates& rates) {
  for (const auto& [name, value] : {std::pair<const char*, int>{"--pose-every", rates.pose_every},
                                    {"--uncertainty-every", rates.uncertainty_every},
                                    {"--status-every", rates.status_every}}) {
    if (value < 1 || value > firmware::kMaxPublishEvery) {
      throw InputError(fmt::format("{} must be 1 to {} cycles, got {}", name, firmware::kMaxPublishEvery, value));
    }
  }
}

namespace {

protocol::BusTraffic traffic_of(const BusOptions& options) {
  protocol::BusTraffic traffic;
  traffic.segments = options.segments;
  traffic.cycle_hz = static_cast<std::uint32_t>(options.rate_hz + 0.5);
  traffic.streaming = options.streaming;
  traffic.rates = options.rates;
  return traffic;
}

}  // namespace

std::vector<NamedBudget> bus_budgets_of(const BusOptions& options) {
  if (options.cia402_drives > 0) return cia402_budgets_of(options);
  const protocol::BusTraffic traffic = traffic_of(options);
  const BusLayout& layout = options.layout;
  if (!layout.drives_bus) {
    return {{"", layout.bus, protocol::bus_budget(traffic, bus_setup(layout.bus, protocol::BusRole::shared))}};
  }
  return {{"host", layout.bus, protocol::bus_budget(traffic, bus_setup(layout.bus, protocol::BusRole::host))},
          {"drives", layout.drives, protocol::bus_budget(traffic, bus_setup(layout.drives, protocol::BusRole::drives))}};
}

// The host's bus without the drives' traffic, then each CANopen bus, the
// first ones with a drive more when they do not share evenly.
std::vector<NamedBudget> cia402_budgets_of(const BusOptions& options) {
  const protocol::BusTraffic traffic = traffic_of(options);
  const BusLayout& layout = options.layout;
  std::vector<NamedBudget> budgets{
      {"host", layout.bus, protocol::bus_budget(traffic, bus_setup(layout.bus, protocol::BusRole::host))}};
  const BusLine& line = layout.drives.bitrate != 0 ? layout.drives : layout.bus;
  for (int b = 0; b < options.cia402_buses; ++b) {
    const int drives = !options.cia402_per_bus.empty()
                           ? options.cia402_per_bus[std::size_t(b)]
                           : options.cia402_drives / options.cia402_buses + (b < options.cia402_drives % options.cia402_buses);
    budgets.push_back({fmt::format("CANopen bus {} ({} CiA 402 drives)", b + 1, drives), line,
                       firmware::canopen::cia402_bus_budget(drives, traffic.cycle_hz,
                                                            static_cast<std::uint16_t>(options.heartbeat_ms),
                                                            bus_setup(line, protocol::BusRole::drives))});
  }
  return budgets;
}

namespace {

std::string rate_text(std::uint32_t bitrate) {
  return bitrate % 1000000 == 0 ? fmt::format("{} Mbit/s", bitrate / 1000000)
         : bitrate % 1000 == 0  ? fmt::format("{} kbit/s", bitrate / 1000)
                                : fmt::format("{} bit/s", bitrate);
}

// "the host's", "the drives'".
bool is_canopen(const std::string& name) { return name.rfind("CANopen", 0) == 0; }
std::string possessive(const std::string& name) {
  return is_canopen(name) ? name : "the " + name + (name == "drives" ? "'" : "'s");
}
std::string bus_name(const NamedBudget& bus) {
  if (is_canopen(bus.name)) return "the " + bus.name;
  return bus.name.empty() ? "the CAN bus" : possessive(bus.name) + " CAN bus";
}

std::string configuration_text(const BusOptions& options, const NamedBudget& bus) {
  if (is_canopen(bus.name))
    return fmt::format("SYNC, RPDO1 and TPDO1 at {:g} Hz, heartbeats every {} ms, {}", options.rate_hz,
                       options.heartbeat_ms, bus_line_text(bus.line));
  return fmt::format("{} segment{} at {:g} Hz{}, {}{}", options.segments, options.segments == 1 ? "" : "s",
                     options.rate_hz, options.streaming ? ", a target streamed every cycle" : "",
                     bus_line_text(bus.line), bus.name.empty() ? "" : ", " + possessive(bus.name) + " traffic");
}

}  // namespace

std::string bus_line_text(const BusLine& line) {
  switch (line.format) {
    case hal::CanFormat::classical: return "classical CAN at " + rate_text(line.bitrate);
    case hal::CanFormat::fd: return "CAN FD at " + rate_text(line.bitrate);
    case hal::CanFormat::fd_bit_rate_switch:
      return "CAN FD at " + rate_text(line.bitrate) + ", data at " + rate_text(line.data_bitrate);
  }
  return "";
}

std::string format_bus_budgets(const std::vector<NamedBudget>& budgets, const BusOptions& options) {
  std::string text;
  for (const NamedBudget& bus : budgets) {
    const protocol::BusBudget& budget = bus.budget;
    if (is_canopen(bus.name)) {
      text += fmt::format("bus budget of the {}: {}\n", bus.name, configuration_text(options, bus));
    } else {
      text += fmt::format("bus budget{}: {}; pose every {}, radii at most every {}, STATUS/STATS every {} cycles\n",
                          bus.name.empty() ? "" : " of " + possessive(bus.name) + " bus",
                          configuration_text(options, bus), options.rates.pose_every,
                          options.rates.uncertainty_every, options.rates.status_every);
    }
    text += fmt::format("  {:<20} {:>10} {:>11} {:>8}\n", "message", "frames/s", "worst bits", "load");
    for (int i = 0; i < budget.message_count; ++i) {
      const protocol::MessageLoad& line = budget.messages[i];
      text += fmt::format("  {:<20} {:>10.1f} {:>11} {:>7.1f}%\n", line.name, line.frames_per_s, line.worst_bits,
                          100.0 * line.load);
    }
    text += fmt::format("  {:<20} {:>10.1f} {:>11} {:>7.1f}%  (without stuffing {:.1f} %; limit {:.0f} %: {})\n",
                        "total", budget.frames_per_s, "", 100.0 * budget.load, 100.0 * budget.unstuffed_load,
                        100.0 * firmware::kMaxBusLoad, budget.fits() ? "fits" : "does not fit");
  }
  return text;
}

std::string bus_budget_refusal(const std::vector<NamedBudget>& budgets, const BusOptions& options) {
  std::string over;
  bool host_over = false;
  for (const NamedBudget& bus : budgets) {
    if (bus.budget.fits()) continue;
    host_over = host_over || !is_canopen(bus.name);
    over += fmt::format("{}{} would carry up to {:.1f} % of its time ({}; worst-case stuffing)",
                        over.empty() ? "" : " and ", bus_name(bus), 100.0 * bus.budget.load,
                        configuration_text(options, bus));
  }
  if (over.empty()) return "";
  if (!host_over) {
    // Only CANopen buses: the drives' frames do not depend on what the
    // runtime publishes, and CiA 402 drives send classical frames.
    return fmt::format("{}, above the {:.0f} % limit: lower the cycle rate (--rate), raise the drives' bit rate "
                       "(--drives-bitrate) or spread the drives over more buses (--cia402-buses, at most {})",
                       over, 100.0 * firmware::kMaxBusLoad, firmware::kMaxDriveBuses);
  }
  std::vector<std::string> ways{"publish less often (--pose-every, --uncertainty-every, --status-every)",
                                 "lower the cycle rate (--rate)", "raise the bit rate (--bitrate)"};
  if (!std::all_of(budgets.begin(), budgets.end(), [](const NamedBudget& bus) {
        return bus.line.format == hal::CanFormat::fd_bit_rate_switch;
      })) {
    ways.push_back("send CAN FD frames (--can-format fd-brs, --data-bitrate)");
  }
  if (options.cia402_drives > 0) {
    ways.push_back("spread the drives over more buses (--cia402-buses, at most 4)");
  } else if (!options.layout.drives_bus) {
    ways.push_back("put the drives on a bus of their own (" + options.layout.drives_option + ")");
  }
  std::string listed;
  for (std::size_t i = 0; i < ways.size(); ++i) {
    listed += (i == 0 ? "" : i + 1 == ways.size() ? " or " : ", ") + ways[i];
  }
  return fmt::format("{}, above the {:.0f} % limit: {}", over, 100.0 * firmware::kMaxBusLoad, listed);
}

namespace {

Json budget_json(const protocol::BusBudget& budget) {
  Json result;
  result["load"] = budget.load;
  result["unstuffed_load"] = budget.unstuffed_load;
  result["frames_per_s"] = budget.frames_per_s;
  result["limit"] = firmware::kMaxBusLoad;
  result["fits"] = budget.fits();
  Json messages = Json::array();
  for (int i = 0; i < budget.message_count; ++i) {
    const protocol::MessageLoad& line = budget.messages[i];
    messages.push_back({{"message", line.name},
                        {"frames_per_s", line.frames_per_s},
                        {"worst_bits", line.worst_bits},
                        {"load", line.load}});
  }
  result["messages"] = messages;
  return result;
}

}  // namespace

CommandOutput run_bus(BusOptions options) {
  validate_bus_options(options);
  const std::vector<NamedBudget> budgets = bus_budgets_of(options);
  CommandOutput output;
  if (options.json) {
    // One bus: its budget; two: {"buses": [{"bus": "host", ...}, {"bus": "drives", ...}], "fits": ...}.
    Json result;
    if (budgets.size() == 1) {
      result = budget_json(budgets.front().budget);
    } else {
      bool fits = true;
      result["buses"] = Json::array();
      for (const NamedBudget& bus : budgets) {
        Json one = budget_json(bus.budget);
        one["bus"] = bus.name;
        result["buses"].push_back(one);
        fits = fits && bus.budget.fits();
      }
      result["fits"] = fits;
    }
    output.text = result.dump() + "\n";
  } else {
    output.text = format_bus_budgets(budgets, options);
  }
  output.failure = bus_budget_refusal(budgets, options);
  return output;
}

void register_bus_command(CLI::App& app, CommandOutput& output) {
  auto options = std::make_shared<BusOptions>();
  CLI::App* command =
      app.add_subcommand("bus", "The CAN bus budget of a configuration: every message's share, the worst-case load");
  command->add_option("--segments", options->segments, "Segments (one cable frame each way per segment)")
      ->capture_default_str();
  command->add_option("--rate", options->rate_hz, "Cycle rate, Hz")->capture_default_str();
  command->add_flag("--streaming", options->streaming,
                    "The host streams a pose target every cycle (and the runtime sends setpoints every cycle)");
  add_publish_rate_options(*command, options->rates);
  add_bus_layout_options(*command, options->layout, "The bus's bit rate, bit/s (CAN FD: the arbitration rate)", true);
  command->add_option("--cia402", options->cia402_drives,
                      "CiA 402 drives over CANopen instead of the protocol's drives: how many (one per cable), on "
                      "buses of their own at the drives' format and rate (--drives-bitrate, else --bitrate)");
  command->add_option("--cia402-buses", options->cia402_buses, "Buses the CiA 402 drives are spread over (1 to 4)")
      ->capture_default_str();
  command->add_option("--heartbeat-ms", options->heartbeat_ms, "The CiA 402 drives' heartbeat period, ms")
      ->capture_default_str();
  command->add_flag("--json", options->json, "Print one JSON object instead of the table");
  command->callback([options, &output] { output = run_bus(*options); });
}

}  // namespace cdcr::cli
