// The C++ half of the R5F start-up: vectors.S has set the exception mode
// stacks, enabled the FPU and the instruction cache, and calls
// cdcr_zynqmp_start in System mode.

#include <cstdint>

#include <cdcr/baremetal/startup.hpp>

#include "cdcr/zynqmp/console.hpp"

extern "C" {
// ISO C++ forbids calling main, so the start-up reaches the program's main
// through another name for the same symbol.
int cdcr_zynqmp_application_main() __asm__("main");
[[noreturn]] void cdcr_zynqmp_start();
[[noreturn]] void cdcr_zynqmp_exception(std::uint32_t exception, std::uint32_t return_address);
}

extern "C" [[noreturn]] void cdcr_zynqmp_start() {
  cdcr::baremetal::initialise_data_and_bss();
  // The UART before the static constructors, so that a fault or a failed
  // assertion in one of them is reported.
  cdcr::zynqmp::console_init();
  cdcr::baremetal::run_static_constructors();

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
