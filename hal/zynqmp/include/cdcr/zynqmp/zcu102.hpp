#pragma once
// The Zynq UltraScale+ MPSoC peripherals the R5F board uses, at their
// addresses in the low-power domain (UG1085, and QEMU's xlnx-zcu102).

#include <cstdint>

namespace cdcr::zynqmp {

inline constexpr std::uintptr_t kUart0Base = 0xFF000000u;
inline constexpr std::uintptr_t kCan0Base = 0xFF060000u;
inline constexpr std::uintptr_t kCan1Base = 0xFF070000u;
inline constexpr std::uintptr_t kTtc0Base = 0xFF110000u;
// The CAN controllers' reference clock (CAN_REF_CLK) as QEMU models it, and
// as the zcu102's clock set-up gives it.
inline constexpr std::uint32_t kCanReferenceClockHz = 24'000'000u;
// The TTCs' clock as QEMU models it (hw/timer/cadence_ttc.c); on silicon
// the LPD_LSBUS clock, about 100 MHz.
inline constexpr std::uint32_t kTtcClockHz = 133'000'000u;

}  // namespace cdcr::zynqmp
