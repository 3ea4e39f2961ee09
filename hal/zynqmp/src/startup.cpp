// The C++ half of the R5F start-up: vectors.S has set the exception mode
// stacks, enabled the FPU and the instruction cache, and calls
// cdcr_zynqmp_start in System mode.

#include <cstdint>

#include "cdcr/zynqmp/console.hpp"

extern "C" {
// From zcu102_r5f.ld.
extern std::uint32_t __data_load_start__[];
extern std::uint32_t __data_start__[];
extern std::uint32_t __data_end__[];
extern std::uint32_t __bss_start__[];
extern std::uint32_t __bss_end__[];
extern void (*__init_array_start[])();
extern void (*__init_array_end[])();

// ISO C++ forbids calling main, so the start-up reaches the program's main
// through another name for the same symbol.
int cdcr_zynqmp_application_main() __asm__("main");
[[noreturn]] void cdcr_zynqmp_start();
[[noreturn]] void cdcr_zynqmp_exception(std::uint32_t exception, std::uint32_t return_address);
}

extern "C" [[noreturn]] void cdcr_zynqmp_start() {
  const std::uint32_t* from = __data_load_start__;
  for (std::uint32_t* to = __data_start__; to < __data_end__;) *to++ = *from++;
  for (std::uint32_t* to = __bss_start__; to < __bss_end__;) *to++ = 0;
  // The UART before the static constructors, so that a fault or a failed
  // assertion in one of them is reported.
  cdcr::zynqmp::console_init();
  // -nostartfiles leaves no _init to run the static constructors.
  for (void (**constructor)() = __init_array_start; constructor < __init_array_end; ++constructor) (*constructor)();

  cdcr::zynqmp::exit(cdcr_zynqmp_application_main());
}

namespace {

// Indexed by the numbers vectors.S passes.
const char* const kExceptionNames[] = {"reset", "undefined instruction", "SVC", "prefetch abort",
                                       "data abort", "reserved", "IRQ", "FIQ"};

}  // namespace

extern "C" [[noreturn]] void cdcr_zynqmp_exception(std::uint32_t exception, std::uint32_t return_address) {
  cdcr::zynqmp::console_write("HARDFAULT: ");
  cdcr::zynqmp::console_write(exception < 8 ? kExceptionNames[exception] : "unknown");
  cdcr::zynqmp::console_write(", return address ");
  cdcr::zynqmp::console_write_hex(return_address);
  cdcr::zynqmp::console_write("\n");
  // An SVC taken as an exception means QEMU's semihosting is off: exiting
  // through it again would come straight back here.
  if (exception == 2) {
    for (;;) asm volatile("wfi");
  }
  cdcr::zynqmp::exit(cdcr::zynqmp::ExitCode::hard_fault);
}
