#pragma once
// QEMU's MPS2 boards as the runtime sees them: SysTick on the 25 MHz core
// clock, semihosting console, the model image in .cdcr_model, and a mailbox
// CAN (the boards have no CAN controller) that the program on the board
// drives in place of the bus.

#include <cdcr/cortexm/flash_model_storage.hpp>
#include <cdcr/cortexm/mailbox_can.hpp>
#include <cdcr/cortexm/semihosting_console.hpp>
#include <cdcr/cortexm/systick.hpp>
#include <cdcr/firmware/capacity.hpp>
#include <cdcr/hal/hal.hpp>

namespace cdcr::boards::mps2 {

inline constexpr std::uint32_t kCoreClockHz = 25'000'000;
inline constexpr std::int64_t kCyclePeriodNs = 1'000'000;  // 1 kHz
// A controller's receive FIFO is a few frames deep; a cycle's traffic (one
// cable frame per segment, three target frames) fits with room to spare.
inline constexpr std::size_t kMailboxDepth = 32;

struct Board {
  cortexm::SysTickTimer timer{kCoreClockHz};
  cortexm::MailboxCan<kMailboxDepth, firmware::kMaxCanFilters> can;
  cortexm::FlashModelStorage model_storage;
  cortexm::SemihostingConsole console;

  hal::Hal hal() { return hal::Hal{timer, timer, can, model_storage, console}; }
};

}  // namespace cdcr::boards::mps2
