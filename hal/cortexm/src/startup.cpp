// Reset and fault handling for QEMU's MPS2 boards (mps2-an500 Cortex-M7,
// mps2-an386 Cortex-M4F): code and constants in the 4 MiB at 0x00000000,
// data, stack and bss in the 4 MiB at 0x20000000 (mps2.ld).

#include <cstdint>

#include <cdcr/baremetal/startup.hpp>

#include "cdcr/cortexm/semihosting.hpp"

extern "C" {
extern std::uint32_t __stack_top__[];  // mps2.ld

// ISO C++ forbids calling main, so the startup code reaches the program's
// main through another name for the same symbol.
int cdcr_cortexm_application_main() __asm__("main");
[[noreturn]] void cdcr_cortexm_reset_handler();
[[noreturn]] void cdcr_cortexm_fault_handler();
void cdcr_cortexm_systick_handler();  // systick.cpp
}

namespace {

// Coprocessor access control: full access to CP10 and CP11, the FPU.
volatile std::uint32_t& cpacr() { return *reinterpret_cast<volatile std::uint32_t*>(0xE000ED88u); }
constexpr std::uint32_t kCpacrFpuFullAccess = 0xFu << 20;

using Handler = void (*)();

}  // namespace

extern "C" [[noreturn]] void cdcr_cortexm_fault_handler() {
  cdcr::cortexm::console_write("HARDFAULT\n");
  cdcr::cortexm::exit(cdcr::cortexm::ExitCode::hard_fault);
}

extern "C" [[noreturn]] void cdcr_cortexm_reset_handler() {
  // Before anything else: the compiler may use FPU registers anywhere, and
  // the first FPU instruction faults while the coprocessor is disabled.
  cpacr() = cpacr() | kCpacrFpuFullAccess;
  asm volatile("dsb\n\tisb" ::: "memory");

  cdcr::baremetal::initialise_data_and_bss();
  cdcr::baremetal::run_static_constructors();

  cdcr::cortexm::exit(cdcr_cortexm_application_main());
}

// Exceptions 1..15. MemManage, BusFault and UsageFault are disabled after
// reset and escalate to HardFault; they share its handler anyway in case
// something enables them. SysTick is the only interrupt in use; a board's
// CAN controller adds its own entries after these.
extern "C" __attribute__((section(".vectors"), used)) const Handler cdcr_cortexm_vector_table[16] = {
    reinterpret_cast<Handler>(__stack_top__),
    cdcr_cortexm_reset_handler,
    cdcr_cortexm_fault_handler,  // NMI
    cdcr_cortexm_fault_handler,  // HardFault
    cdcr_cortexm_fault_handler,  // MemManage
    cdcr_cortexm_fault_handler,  // BusFault
    cdcr_cortexm_fault_handler,  // UsageFault
    nullptr,
    nullptr,
    nullptr,
    nullptr,
    cdcr_cortexm_fault_handler,  // SVCall
    cdcr_cortexm_fault_handler,  // DebugMonitor
    nullptr,
    cdcr_cortexm_fault_handler,  // PendSV
    cdcr_cortexm_systick_handler,
};
