// cdcr-runtime --can: the runtime on a SocketCAN interface in real time.

#include <cmath>
#include <csignal>
#include <cstdio>
#include <stdexcept>
#include <string>

#include <cdcr/firmware/runtime.hpp>
#include <cdcr/hal/shifted_can_bus.hpp>

#include "cli/cli_errors.hpp"
#if CDCR_HAVE_LINUX_PLATFORM
#include "cdcr/linux/file_flash.hpp"
#include "cdcr/linux/mapped_model_storage.hpp"
#include "cdcr/linux/posix_time.hpp"
#include "cdcr/linux/socketcan_bus.hpp"
#include "cdcr/linux/stdio_console.hpp"
#endif
#include "runtime_modes.hpp"

namespace cdcr::runtime_host {

namespace fw = cdcr::firmware;
namespace model = cdcr::model;
namespace protocol = cdcr::firmware::protocol;
using cli::InputError;

#if CDCR_HAVE_LINUX_PLATFORM
namespace {

volatile std::sig_atomic_t stop_requested = 0;

void request_stop(int) { stop_requested = 1; }

void print_cycle_statistics(const fw::Runtime& runtime, const cdcr::hal::CanErrorCounters& can, double rate_hz,
                            double elapsed_s) {
  const fw::CycleStatistics& stats = runtime.statistics();
  std::printf("state %s, fault: %s\n", fw::to_string(runtime.state()), fw::to_string(runtime.active_fault()));
  std::printf("cycles %u at %.0f Hz (%.3f s), overruns %u, rejected frames %u, rejected cable sets %u, stale events %u\n",
              stats.cycles, rate_hz, elapsed_s, stats.overruns, stats.rejected_frames, stats.rejected_cable_sets,
              stats.stale_events);
  std::printf("cycle execution: max %.1f us, mean %.1f us; start jitter max %.1f us\n",
              double(stats.execution_max_ns) * 1e-3, double(stats.execution_mean_ns()) * 1e-3,
              double(stats.jitter_max_ns) * 1e-3);
  std::printf("poses published %u, targets received %u; CAN tx dropped %u, rx overruns %u, bus errors %u\n",
              stats.poses_published, stats.targets_received, can.tx_dropped, can.rx_overruns, can.bus_errors);
}

}  // namespace

// The runtime on a real bus: the same object the board runs, on the Linux
// backends, until the duration ends or a signal asks it to stop.
int run_on_socketcan(const std::string& image_path, const std::string& interface_name,
                     const std::string& drives_interface, double rate_hz, double seconds, const std::string& flash_dir,
                     bool spin, const BusChoice& bus_choice) {
  require_rate(rate_hz);
  if (seconds != 0 && (!(seconds > 0) || !(seconds <= 86400))) {
    throw std::invalid_argument("--seconds must be in (0, 86400]");
  }
  static cdcr::linux_host::SocketCanBus bus;
  static cdcr::linux_host::SocketCanBus drives_bus;
  static cdcr::linux_host::PosixMonotonicClock clock;
  static cdcr::linux_host::PosixPeriodicTimer timer{
      clock, spin ? cdcr::linux_host::ReleaseWait::spin : cdcr::linux_host::ReleaseWait::sleep};
  static cdcr::linux_host::MappedModelStorage storage;
  static cdcr::linux_host::StdioConsole console{stderr};
  std::string error;
  if (!image_path.empty() && !storage.map_file(image_path, error)) throw InputError(error);
  const cli::BusLayout& layout = bus_choice.layout;
  if (!bus.open(interface_name, error, layout.bus.format != cdcr::hal::CanFormat::classical)) {
    throw InputError("CAN interface " + interface_name + ": " + error);
  }
  const bool two_buses = !drives_interface.empty();
  if (two_buses && !drives_bus.open(drives_interface, error, layout.drives.format != cdcr::hal::CanFormat::classical)) {
    throw InputError("CAN interface " + drives_interface + " (--drives-can): " + error);
  }
  // With a flash directory, models deployed over CAN (A/B slots) run in
  // preference to --image, which stays the fallback.
  static cdcr::linux_host::FileFlash flash;
  if (!flash_dir.empty() && !flash.open_directory(flash_dir, error)) throw InputError("--flash-dir: " + error);

  struct sigaction action {};
  action.sa_handler = request_stop;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);

  static cdcr::hal::ShiftedCanBus runtime_can(bus, protocol::id_offset(bus_choice.id_base));
  static cdcr::hal::ShiftedCanBus runtime_drives_can(drives_bus, protocol::id_offset(bus_choice.id_base));
  static const cdcr::hal::Hal hal{clock,   timer, runtime_can, storage, console, flash_dir.empty() ? nullptr : &flash,
                                  two_buses ? &runtime_drives_can : nullptr};
  static fw::Runtime runtime(hal, fw::Geometry::prototype());
  if (!runtime.set_can_formats(layout.bus.format, two_buses ? layout.drives.format : layout.bus.format)) {
    throw InputError("the CAN interfaces do not take the formats asked for");
  }
  runtime.init();
  runtime.set_publish_rates(bus_choice.rates);
  check_bus_budget(runtime.geometry().segment_count, rate_hz, bus_choice.streaming, bus_choice);

  const auto period_ns = static_cast<std::int64_t>(std::llround(1e9 / rate_hz));
  const std::int64_t start_ns = clock.now_ns();
  const std::int64_t end_ns = seconds > 0 ? start_ns + static_cast<std::int64_t>(std::llround(seconds * 1e9)) : 0;
  timer.start(period_ns);
  while (stop_requested == 0) {
    const cdcr::hal::TimerTick tick = timer.wait_next();
    if (end_ns != 0 && tick.release_ns > end_ns) break;
    runtime.run_cycle(tick);
  }
  print_cycle_statistics(runtime, bus.error_counters(), rate_hz, double(clock.now_ns() - start_ns) * 1e-9);
  if (two_buses) {
    const cdcr::hal::CanErrorCounters can = drives_bus.error_counters();
    std::printf("drives' bus %s: CAN tx dropped %u, rx overruns %u, bus errors %u\n", drives_interface.c_str(),
                can.tx_dropped, can.rx_overruns, can.bus_errors);
  }
  std::fflush(stdout);
  return 0;
}
#else
int run_on_socketcan(const std::string&, const std::string&, const std::string&, double, double,
                     const std::string&, bool, const BusChoice&) {
  throw InputError("--can needs a Linux host (SocketCAN)");
}
#endif

}  // namespace cdcr::runtime_host
