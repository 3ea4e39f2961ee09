#pragma once
// The R5F board's console on uart0 (the Cadence UART at 0xFF000000), and the
// exit status a program under QEMU ends with. Text goes to the UART only;
// semihosting serves the exit status alone, so the board reports the same way
// with or without a debugger. console.cpp defines the board's console_write
// and exit, which drains the UART first; the formatting and the exit codes
// are every bare-metal board's (cdcr/baremetal/console.hpp).

#include <cdcr/baremetal/console.hpp>

namespace cdcr::zynqmp {

using namespace cdcr::baremetal;

// The UART is set up by the start-up code before main.
void console_init();

}  // namespace cdcr::zynqmp
