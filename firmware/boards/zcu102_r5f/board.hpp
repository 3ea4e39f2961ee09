#pragma once
// The Cortex-R5F of QEMU's xlnx-zcu102 as the runtime sees it: the cycle
// counter as clock and timer, can0 through the Xilinx CAN driver at
// 1 Mbit/s, the model image in .cdcr_model, and the console on uart0; and,
// around the runtime, the cycle loop's watchdog on TTC0. The deployable
// program puts the drives on can1 (DrivesBus), a bus of their own.

#include <cdcr/firmware/capacity.hpp>
#include <cdcr/firmware/protocol/bus_budget.hpp>
#include <cdcr/hal/hal.hpp>
#include <cdcr/zynqmp/can_bit_timing.hpp>
#include <cdcr/zynqmp/console.hpp>
#include <cdcr/zynqmp/cycle_counter_timer.hpp>
#include <cdcr/zynqmp/section_model_storage.hpp>
#include <cdcr/zynqmp/ttc_watchdog.hpp>
#include <cdcr/zynqmp/uart_console.hpp>
#include <cdcr/zynqmp/xilinx_can.hpp>
#include <cdcr/zynqmp/zcu102.hpp>

namespace cdcr::boards::zcu102_r5f {

namespace protocol = firmware::protocol;

inline constexpr std::int64_t kCyclePeriodNs = 1'000'000;  // 1 kHz
inline constexpr std::uint32_t kCanBitrate = 1'000'000;
inline constexpr zynqmp::CanBitTiming kCanTiming =
    zynqmp::compute_bit_timing(zynqmp::kCanReferenceClockHz, kCanBitrate);
static_assert(zynqmp::bitrate(kCanTiming, zynqmp::kCanReferenceClockHz) == kCanBitrate,
              "1 Mbit/s is exact from the CAN reference clock");
// Frames the driver holds between cycles beyond the controller's own 64: a
// cycle's traffic (one cable frame per segment, three target frames) fits
// with room to spare.
inline constexpr std::size_t kCanRxQueueDepth = 32;
static_assert(firmware::kMaxCanFilters <= zynqmp::kXilinxCanFilters,
              "the controller holds every acceptance filter the runtime sets");
// The instructions a cycle may take (Runtime::run_cycle, counted under
// QEMU -icount shift=0 by zynqmp.workload): a 1 ms period of an R5F at
// 500 MHz (the ZynqMP's RPU runs at 500 to 600 MHz by speed grade) at half
// an instruction a clock, which its single-issue VFPv3 (no fused
// multiply-add) and a DDR behind 32 KiB caches allow for the GP loops; the
// Cortex-M boards' 80,000 and 120,000 are the same kind of figure for them.
// The runtime spreads IK over cycles with the portable work costs
// (model/arch/portable), not yet measured on this core.
inline constexpr std::uint32_t kCycleBudgetInstructions = 250'000;
// Five periods: a cycle late by up to two periods is survived (it, the wait
// for the next release and the next cycle fit; the runtime counts the
// missed releases); a cycle that has not come back after five periods, or
// cycles that keep running late, end the program.
inline constexpr std::int64_t kWatchdogTimeoutNs = 5 * kCyclePeriodNs;

// What the board does when its watchdog expires. QEMU 7.2 emulates no reset
// the RPU could ask for (no CRL_APB, no system watchdog: ttc_watchdog.hpp),
// so the board reports on the UART and ends with ExitCode::watchdog_expired;
// on silicon this is where the RPU resets itself (CRL_APB RST_LPD_TOP).
[[noreturn]] inline void watchdog_reset(const hal::TimerTick& tick, std::int64_t now_ns) {
  zynqmp::console_write("WATCHDOG: no cycle completed in time for ");
  zynqmp::console_write_int(static_cast<std::int32_t>(kWatchdogTimeoutNs / 1000));
  zynqmp::console_write(" us; the cycle released at ");
  zynqmp::console_write_int(static_cast<std::int32_t>(tick.release_ns / 1000));
  zynqmp::console_write(" us ended at ");
  zynqmp::console_write_int(static_cast<std::int32_t>(now_ns / 1000));
  zynqmp::console_write(" us: reset\n");
  zynqmp::exit(zynqmp::ExitCode::watchdog_expired);
}

// The deployable program's buses: the host's traffic on can0, the drives'
// (CABLE_FEEDBACK in, the setpoints out) on can1, both classical (the
// ZynqMP's controllers have no CAN FD) at kCanBitrate, estimating at the
// board's cycle rate. QEMU's controllers move frames in no time, so the load
// is the computed worst case only (protocol/bus_budget.hpp), which the board
// states at start-up for the robot the runtime loaded (the image's segments,
// or the fallback geometry's) and the runtime's publish rates.
inline protocol::BusTraffic board_traffic(int segments, const firmware::PublishRates& rates) {
  protocol::BusTraffic traffic;
  traffic.segments = segments;
  traffic.cycle_hz = static_cast<std::uint32_t>(1'000'000'000 / kCyclePeriodNs);
  traffic.rates = rates;
  return traffic;
}
inline protocol::BusSetup board_bus(protocol::BusRole role) {
  protocol::BusSetup bus;
  bus.rates.nominal = kCanBitrate;
  bus.role = role;
  return bus;
}

// Prints one bus's computed worst-case load; false if it is above the limit.
inline bool state_bus_budget(const char* name, const protocol::BusTraffic& traffic,
                             protocol::BusRole role) {
  const protocol::BusBudget budget = protocol::bus_budget(traffic, board_bus(role));
  zynqmp::console_write(name);
  zynqmp::console_write(": worst case ");
  zynqmp::console_write_fixed(100.0 * budget.load, 1);
  zynqmp::console_write(" % of 1 Mbit/s (");
  zynqmp::console_write_fixed(budget.frames_per_s, 0);
  zynqmp::console_write(budget.fits() ? " frames/s), fits\n" : " frames/s), above the limit\n");
  return budget.fits();
}

// The budget of both buses, computed, not measured: the board refuses to
// run a configuration whose worst case does not fit.
inline bool state_bus_budgets(int segments, const firmware::PublishRates& rates) {
  const protocol::BusTraffic traffic = board_traffic(segments, rates);
  zynqmp::console_write("bus budget, computed (QEMU's CAN has no bit timing): ");
  zynqmp::console_write_int(segments);
  zynqmp::console_write(" segments at ");
  zynqmp::console_write_int(static_cast<std::int32_t>(traffic.cycle_hz));
  zynqmp::console_write(" Hz, limit ");
  zynqmp::console_write_fixed(100.0 * firmware::kMaxBusLoad, 0);
  zynqmp::console_write(" %\n");
  const bool host = state_bus_budget("  can0, the host's bus", traffic, protocol::BusRole::host);
  const bool drives = state_bus_budget("  can1, the drives' bus", traffic, protocol::BusRole::drives);
  return host && drives;
}

// can1 for the drives, beside the Board's can0.
struct DrivesBus {
  zynqmp::XilinxCan<kCanRxQueueDepth> can{zynqmp::kCan1Base};
  bool start() { return can.start(kCanTiming); }
};

struct Board {
  zynqmp::CycleCounterTimer timer{zynqmp::kQemuCycleCounterHz};
  zynqmp::XilinxCan<kCanRxQueueDepth> can{zynqmp::kCan0Base};
  zynqmp::SectionModelStorage model_storage;
  zynqmp::UartConsole console;
  zynqmp::TtcWatchdog watchdog{zynqmp::kTtc0Base, zynqmp::kTtcClockHz};

  // Brings can0 onto the bus; false if the controller does not come up.
  bool start_can() { return can.start(kCanTiming); }
  hal::Hal hal() { return hal::Hal{timer, timer, can, model_storage, console}; }
  // With the drives on a bus of their own: `host` and `drives` are can0
  // and a DrivesBus's can1, or buses over them (hal::ShiftedCanBus).
  hal::Hal hal(hal::CanBus& host, hal::CanBus& drives) {
    return hal::Hal{timer, timer, host, model_storage, console, nullptr, &drives};
  }

  // The 1 kHz releases and the watchdog, started together.
  void start_cycles() {
    timer.start(kCyclePeriodNs);
    watchdog.start(kWatchdogTimeoutNs);
  }

  // One cycle under the watchdog: waits for the release, runs cycle(tick),
  // then guard(tick).
  template <typename Cycle>
  void run_guarded(Cycle&& cycle) {
    const hal::TimerTick tick = timer.wait_next();
    cycle(tick);
    guard(tick);
  }

  // After the cycle released at tick: an expired watchdog resets the board;
  // otherwise the cycle kicks it if it completed within its period.
  void guard(const hal::TimerTick& tick) {
    const std::int64_t now_ns = timer.now_ns();
    if (watchdog.expired()) watchdog_reset(tick, now_ns);
    if (now_ns - tick.release_ns <= kCyclePeriodNs) watchdog.kick();
  }
};

}  // namespace cdcr::boards::zcu102_r5f
