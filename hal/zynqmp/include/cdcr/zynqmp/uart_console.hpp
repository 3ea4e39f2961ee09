#pragma once
// The runtime's log lines on the board's UART (console.hpp).

#include <cdcr/baremetal/line_console.hpp>

namespace cdcr::zynqmp {

using UartConsole = baremetal::LineConsole;

}  // namespace cdcr::zynqmp
