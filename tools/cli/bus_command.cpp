#include "bus_command.hpp"

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

void add_bitrate_option(CLI::App& command, std::uint32_t& bitrate, const std::string& what) {
  command.add_option("--bitrate", bitrate, what)->capture_default_str();
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

void validate_bus_options(const BusOptions& options) {
  if (options.segments < 1 || options.segments > firmware::kMaxSegments) {
    throw InputError(fmt::format("--segments must be 1 to {}, got {}", firmware::kMaxSegments, options.segments));
  }
  if (!(options.rate_hz > 0.0 && options.rate_hz <= 100000.0)) {
    throw InputError(fmt::format("--rate must be in (0, 100000] Hz, got {}", options.rate_hz));
  }
  if (options.bitrate < 10000 || options.bitrate > 1000000) {
    throw InputError(
        fmt::format("--bitrate must be 10000 to 1000000 bit/s (classical CAN), got {}", options.bitrate));
  }
  validate_publish_rates(options.rates);
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

protocol::BusBudget bus_budget_of(const BusOptions& options) {
  protocol::BusTraffic traffic;
  traffic.segments = options.segments;
  traffic.cycle_hz = static_cast<std::uint32_t>(options.rate_hz + 0.5);
  traffic.streaming = options.streaming;
  traffic.rates = options.rates;
  const protocol::BusSetup bus{hal::CanFormat::classical, {options.bitrate, 0}};
  return protocol::bus_budget(traffic, bus);
}

namespace {

std::string rate_text(std::uint32_t bitrate) {
  return bitrate % 1000000 == 0 ? fmt::format("{} Mbit/s", bitrate / 1000000)
         : bitrate % 1000 == 0  ? fmt::format("{} kbit/s", bitrate / 1000)
                                : fmt::format("{} bit/s", bitrate);
}

std::string configuration_text(const BusOptions& options) {
  return fmt::format("{} segment{} at {:g} Hz{}, classical CAN at {}", options.segments,
                     options.segments == 1 ? "" : "s", options.rate_hz,
                     options.streaming ? ", a target streamed every cycle" : "", rate_text(options.bitrate));
}

}  // namespace

std::string format_bus_budget(const protocol::BusBudget& budget, const BusOptions& options) {
  std::string text = fmt::format("bus budget: {}; pose every {}, radii at most every {}, STATUS/STATS every {} cycles\n",
                                 configuration_text(options), options.rates.pose_every, options.rates.uncertainty_every,
                                 options.rates.status_every);
  text += fmt::format("  {:<20} {:>10} {:>11} {:>8}\n", "message", "frames/s", "worst bits", "load");
  for (int i = 0; i < budget.message_count; ++i) {
    const protocol::MessageLoad& line = budget.messages[i];
    text += fmt::format("  {:<20} {:>10.1f} {:>11} {:>7.1f}%\n", line.message->name, line.frames_per_s,
                        line.worst_bits, 100.0 * line.load);
  }
  text += fmt::format("  {:<20} {:>10.1f} {:>11} {:>7.1f}%  (without stuffing {:.1f} %; limit {:.0f} %: {})\n", "total",
                      budget.frames_per_s, "", 100.0 * budget.load, 100.0 * budget.unstuffed_load,
                      100.0 * firmware::kMaxBusLoad, budget.fits() ? "fits" : "does not fit");
  return text;
}

std::string bus_budget_refusal(const protocol::BusBudget& budget, const BusOptions& options) {
  if (budget.fits()) return "";
  return fmt::format(
      "the CAN bus would carry up to {:.1f} % of its time ({}; worst-case stuffing), above the {:.0f} % limit: "
      "publish less often (--pose-every, --uncertainty-every, --status-every), lower the cycle rate (--rate) or "
      "raise the bit rate (--bitrate)",
      100.0 * budget.load, configuration_text(options), 100.0 * firmware::kMaxBusLoad);
}

CommandOutput run_bus(const BusOptions& options) {
  validate_bus_options(options);
  const protocol::BusBudget budget = bus_budget_of(options);
  CommandOutput output;
  if (options.json) {
    Json result;
    result["load"] = budget.load;
    result["unstuffed_load"] = budget.unstuffed_load;
    result["frames_per_s"] = budget.frames_per_s;
    result["limit"] = firmware::kMaxBusLoad;
    result["fits"] = budget.fits();
    Json messages = Json::array();
    for (int i = 0; i < budget.message_count; ++i) {
      const protocol::MessageLoad& line = budget.messages[i];
      messages.push_back({{"message", line.message->name},
                          {"frames_per_s", line.frames_per_s},
                          {"worst_bits", line.worst_bits},
                          {"load", line.load}});
    }
    result["messages"] = messages;
    output.text = result.dump() + "\n";
  } else {
    output.text = format_bus_budget(budget, options);
  }
  output.failure = bus_budget_refusal(budget, options);
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
  add_bitrate_option(*command, options->bitrate, "The bus's bit rate, bit/s");
  command->add_flag("--json", options->json, "Print one JSON object instead of the table");
  command->callback([options, &output] { output = run_bus(*options); });
}

}  // namespace cdcr::cli
