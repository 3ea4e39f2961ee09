#include "bus_tally.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include <cdcr/firmware/protocol/messages.hpp>
#include <cdcr/hal/shifted_can_bus.hpp>

#include "cli/bus_command.hpp"
#include "cli/cli_errors.hpp"
#include "runtime_modes.hpp"

namespace cdcr::runtime_host {

namespace protocol = cdcr::firmware::protocol;

std::int64_t BusTally::deadline_ns(std::int64_t queued_ns) const {
  if (queued_ns < first_release_ns_) return first_release_ns_;
  const std::int64_t periods = (queued_ns - first_release_ns_) / period_ns_;
  return first_release_ns_ + (periods + 1) * period_ns_;
}

void BusTally::on_transfer(const sim::CanTransfer& transfer) {
  const char* name = nullptr;
  std::uint32_t first_id = 0x800;
  const std::uint32_t id = hal::ShiftedCanBus::unshifted(transfer.frame.id, id_offset_);
  for (const protocol::MessageSpec* m : protocol::kMessages) {
    if (m->carries(id)) name = m->name, first_id = m->id;
  }
  for (const protocol::FdMessageSpec* m : protocol::kFdMessages) {
    if (m->carries(id)) name = m->name, first_id = m->id;
  }
  auto kind = std::find_if(kinds_.begin(), kinds_.end(), [&](const Kind& k) { return k.name == name; });
  if (kind == kinds_.end()) {
    kinds_.push_back(Kind{name, first_id, {}, 0});
    kind = kinds_.end() - 1;
  }
  kind->latency_us.push_back(double(transfer.end_ns - transfer.queued_ns) * 1e-3);
  ++frames_;
  lowest_id_ = std::min(lowest_id_, transfer.frame.id);
  highest_id_ = std::max(highest_id_, transfer.frame.id);
  if (first_release_ns_ >= 0 && period_ns_ > 0 && transfer.end_ns > deadline_ns(transfer.queued_ns)) {
    ++kind->late;
    ++late_;
  }
}

namespace {

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t index = std::min(values.size() - 1, static_cast<std::size_t>(std::ceil(q * double(values.size())) - 1));
  return values[index];
}

}  // namespace

std::string BusTally::table() const {
  std::vector<Kind> kinds = kinds_;
  std::sort(kinds.begin(), kinds.end(), [](const Kind& a, const Kind& b) { return a.id < b.id; });
  std::string text = fmt::format("  {:<20} {:>8} {:>30} {:>6}\n", "message", "frames", "latency p50 / p99 / max (us)",
                                 "late");
  for (const Kind& k : kinds) {
    text += fmt::format("  {:<20} {:>8} {:>12.1f} / {:>6.1f} / {:>6.1f} {:>6}\n",
                        k.name != nullptr ? k.name : "(not the protocol's)", k.latency_us.size(),
                        quantile(k.latency_us, 0.5), quantile(k.latency_us, 0.99),
                        k.latency_us.empty() ? 0.0 : *std::max_element(k.latency_us.begin(), k.latency_us.end()), k.late);
  }
  return text;
}

namespace {

cli::BusOptions bus_options(int segments, double rate_hz, bool streaming, const BusChoice& bus) {
  cli::BusOptions options;
  options.segments = segments;
  options.rate_hz = rate_hz;
  options.streaming = streaming;
  options.rates = bus.rates;
  options.layout = bus.layout;
  if (!bus.cia402_per_bus.empty()) {
    options.cia402_per_bus = bus.cia402_per_bus;
    options.cia402_buses = int(bus.cia402_per_bus.size());
    options.cia402_drives = 0;
    for (int drives : bus.cia402_per_bus) options.cia402_drives += drives;
    options.heartbeat_ms = bus.cia402_heartbeat_ms;
  }
  return options;
}

std::string rates_text(const cli::BusLine& line) {
  return line.format == hal::CanFormat::fd_bit_rate_switch
             ? fmt::format("{} bit/s, data {} bit/s", line.bitrate, line.data_bitrate)
             : fmt::format("{} bit/s", line.bitrate);
}

}  // namespace

std::string timed_bus_report(const std::vector<TimedBus>& buses, std::int64_t now_ns, int segments, double rate_hz,
                             bool streaming, const BusChoice& choice) {
  const std::vector<cli::NamedBudget> budgets = cli::bus_budgets_of(bus_options(segments, rate_hz, streaming, choice));
  std::string text;
  for (std::size_t i = 0; i < buses.size() && i < budgets.size(); ++i) {
    const cli::NamedBudget& planned = budgets[i];
    const BusTally& tally = *buses[i].tally;
    const double measured = BusTally::measured_load(*buses[i].bus, now_ns);
    text += fmt::format("{}bus at {}{}: measured load {:.1f} % over {:.3f} s (the budget's worst case {:.1f} %, "
                        "without stuffing {:.1f} %), {} frames on identifiers 0x{:03X} to 0x{:03X}, {} late for "
                        "their cycle\n",
                        planned.name.empty() ? "" : planned.name + (planned.name == "drives" ? "' " : "'s "),
                        rates_text(planned.line),
                        planned.line.format == hal::CanFormat::classical ? "" : " (CAN FD)", 100.0 * measured,
                        double(now_ns) * 1e-9, 100.0 * planned.budget.load, 100.0 * planned.budget.unstuffed_load,
                        tally.frames(), tally.lowest_id(), tally.highest_id(), tally.late()) +
            tally.table();
  }
  return text;
}

void check_bus_budget(int segments, double rate_hz, bool streaming, const BusChoice& bus) {
  if (bus.layout.bus.bitrate == 0) return;
  cli::BusOptions options = bus_options(segments, rate_hz, streaming, bus);
  cli::validate_bus_options(options);
  const std::vector<cli::NamedBudget> budgets = cli::bus_budgets_of(options);
  std::fputs(cli::format_bus_budgets(budgets, options).c_str(), stdout);
  if (const std::string refusal = cli::bus_budget_refusal(budgets, options); !refusal.empty()) {
    throw cli::InputError(refusal);
  }
}

}  // namespace cdcr::runtime_host
