#pragma once
// Console output and exit status through ARM semihosting (bkpt 0xAB), which
// QEMU answers when run with -semihosting-config enable=on. This is how a
// program under QEMU reports to the test that started it. semihosting.cpp
// defines the board's console_write and exit; the formatting and the exit
// codes are every bare-metal board's (cdcr/baremetal/console.hpp).

#include <cdcr/baremetal/console.hpp>

namespace cdcr::cortexm {

using namespace cdcr::baremetal;

}  // namespace cdcr::cortexm
