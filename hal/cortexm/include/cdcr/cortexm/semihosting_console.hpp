#pragma once
// The runtime's log lines over semihosting. On a board without a debugger
// attached, a UART console takes its place (hal/porting.md).

#include <cdcr/baremetal/line_console.hpp>

namespace cdcr::cortexm {

using SemihostingConsole = baremetal::LineConsole;

}  // namespace cdcr::cortexm
