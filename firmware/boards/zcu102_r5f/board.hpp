#pragma once
// The Cortex-R5F of QEMU's xlnx-zcu102 as the runtime sees it: the cycle
// counter as clock and timer, can0 through the Xilinx CAN driver at
// 1 Mbit/s, the model image in .cdcr_model, and the console on uart0.

#include <cdcr/firmware/capacity.hpp>
#include <cdcr/hal/hal.hpp>
#include <cdcr/zynqmp/can_bit_timing.hpp>
#include <cdcr/zynqmp/cycle_counter_timer.hpp>
#include <cdcr/zynqmp/section_model_storage.hpp>
#include <cdcr/zynqmp/uart_console.hpp>
#include <cdcr/zynqmp/xilinx_can.hpp>
#include <cdcr/zynqmp/zcu102.hpp>

namespace cdcr::boards::zcu102_r5f {

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

struct Board {
  zynqmp::CycleCounterTimer timer{zynqmp::kQemuCycleCounterHz};
  zynqmp::XilinxCan<kCanRxQueueDepth> can{zynqmp::kCan0Base};
  zynqmp::SectionModelStorage model_storage;
  zynqmp::UartConsole console;

  // Brings can0 onto the bus; false if the controller does not come up.
  bool start_can() { return can.start(kCanTiming); }
  hal::Hal hal() { return hal::Hal{timer, timer, can, model_storage, console}; }
};

}  // namespace cdcr::boards::zcu102_r5f
