// cdcr-runtime --can: the runtime on a SocketCAN interface in real time.

#include <cmath>
#include <csignal>
#include <cstdio>
#include <stdexcept>
#include <string>

#include <cdcr/firmware/canopen/cia402_drives.hpp>
#include <cdcr/firmware/runtime.hpp>
#include <cdcr/hal/shifted_can_bus.hpp>

#include "cli/cli_errors.hpp"
#include "cli/drives_config.hpp"
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
volatile std::sig_atomic_t recover_requested = 0;

void request_stop(int) { stop_requested = 1; }
void request_recovery(int) { recover_requested = 1; }

// The CiA 402 drives of --drives-config on their SocketCAN buses.
struct Cia402Setup {
  cdcr::linux_host::SocketCanBus buses[fw::canopen::kMaxDriveBuses];
  cdcr::hal::CanBus* bus_pointers[fw::canopen::kMaxDriveBuses] = {};
  cli::DrivesConfig config;
};

fw::canopen::Cia402Drives* open_cia402_drives(const std::string& path, double rate_hz) {
  static Cia402Setup setup;
  const auto period_us = static_cast<std::uint32_t>(std::llround(1e6 / rate_hz));
  setup.config = cli::read_drives_config(path, period_us);
  std::string error;
  for (std::size_t b = 0; b < setup.config.buses.size(); ++b) {
    if (!setup.buses[b].open(setup.config.buses[b], error, false))
      throw InputError("CAN interface " + setup.config.buses[b] + " (--drives-config bus " + std::to_string(b) +
                       "): " + error);
    setup.bus_pointers[b] = &setup.buses[b];
  }
  static fw::canopen::Cia402Drives drives(setup.config.manager, setup.bus_pointers);
  std::fprintf(stderr, "drives: %d CiA 402 drives on %zu buses, cycle %u us, heartbeat %u ms\n",
               setup.config.manager.drive_count, setup.config.buses.size(), period_us,
               unsigned(setup.config.manager.timing.heartbeat_ms));
  return &drives;
}

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

// One line when the drives' phase changes, with the time since the start.
void report_drives(const fw::canopen::Cia402Drives& drives, std::int64_t elapsed_ns) {
  static fw::canopen::DrivePhase reported = fw::canopen::DrivePhase::reset;
  const fw::canopen::DriveManager& manager = drives.manager();
  if (manager.phase() == reported) return;
  reported = manager.phase();
  std::fprintf(stderr, "drives: %s after %.0f ms", fw::canopen::to_string(reported), double(elapsed_ns) * 1e-6);
  if (reported == fw::canopen::DrivePhase::fault) {
    const fw::canopen::DriveFaultReport& fault = manager.fault();
    std::fprintf(stderr, ": %s, bus %d node %u (cable %d), detail 0x%X", fw::canopen::to_string(fault.fault),
                 fault.cable >= 0 ? int(drives.manager().config().drives[fault.cable].bus) : -1, unsigned(fault.node),
                 fault.cable, unsigned(fault.detail));
    if (fault.object.index != 0)
      std::fprintf(stderr, ", object 0x%04X:%02X", unsigned(fault.object.index), unsigned(fault.object.subindex));
  }
  std::fprintf(stderr, "\n");
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

  struct sigaction recovery {};
  recovery.sa_handler = request_recovery;
  sigemptyset(&recovery.sa_mask);
  sigaction(SIGUSR1, &recovery, nullptr);

  static cdcr::hal::ShiftedCanBus runtime_can(bus, protocol::id_offset(bus_choice.id_base));
  static cdcr::hal::ShiftedCanBus runtime_drives_can(drives_bus, protocol::id_offset(bus_choice.id_base));
  fw::canopen::Cia402Drives* drives =
      bus_choice.cia402_config.empty() ? nullptr : open_cia402_drives(bus_choice.cia402_config, rate_hz);
  static const cdcr::hal::Hal hal{clock,   timer, runtime_can, storage, console, flash_dir.empty() ? nullptr : &flash,
                                  two_buses ? &runtime_drives_can : nullptr, drives};
  static fw::Runtime runtime(hal, fw::Geometry::prototype());
  if (!runtime.set_can_formats(layout.bus.format, two_buses ? layout.drives.format : layout.bus.format)) {
    throw InputError("the CAN interfaces do not take the formats asked for");
  }
  runtime.init();
  if (drives != nullptr && runtime.geometry().cable_count() != drives->manager().drive_count()) {
    throw InputError("--drives-config has " + std::to_string(drives->manager().drive_count()) +
                     " drives, the model's robot " + std::to_string(runtime.geometry().cable_count()) + " cables");
  }
  runtime.set_publish_rates(bus_choice.rates);
  BusChoice planned = bus_choice;
  if (drives != nullptr) {
    const fw::canopen::DriveManagerConfig& config = drives->manager().config();
    planned.cia402_per_bus.assign(std::size_t(config.bus_count), 0);
    for (int i = 0; i < config.drive_count; ++i) ++planned.cia402_per_bus[config.drives[i].bus];
    planned.cia402_heartbeat_ms = config.timing.heartbeat_ms;
  }
  check_bus_budget(runtime.geometry().segment_count, rate_hz, bus_choice.streaming, planned);

  const auto period_ns = static_cast<std::int64_t>(std::llround(1e9 / rate_hz));
  const std::int64_t start_ns = clock.now_ns();
  const std::int64_t end_ns = seconds > 0 ? start_ns + static_cast<std::int64_t>(std::llround(seconds * 1e9)) : 0;
  timer.start(period_ns);
  while (stop_requested == 0) {
    const cdcr::hal::TimerTick tick = timer.wait_next();
    if (end_ns != 0 && tick.release_ns > end_ns) break;
    if (recover_requested != 0) {
      recover_requested = 0;
      std::fprintf(stderr, runtime.recover_drives() ? "drives: recovering\n" : "drives: nothing to recover\n");
    }
    runtime.run_cycle(tick);
    if (drives != nullptr) report_drives(*drives, clock.now_ns() - start_ns);
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
