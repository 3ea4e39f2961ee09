#pragma once
// The part of a bare-metal start-up that is the same on every core: the
// initialised data copied from its load address, the bss zeroed, the static
// constructors run. The symbols come from the board's linker script.

#include <cstdint>

extern "C" {
extern std::uint32_t __data_load_start__[];
extern std::uint32_t __data_start__[];
extern std::uint32_t __data_end__[];
extern std::uint32_t __bss_start__[];
extern std::uint32_t __bss_end__[];
extern void (*__init_array_start[])();
extern void (*__init_array_end[])();
}

namespace cdcr::baremetal {

inline void initialise_data_and_bss() {
  const std::uint32_t* from = __data_load_start__;
  for (std::uint32_t* to = __data_start__; to < __data_end__;) *to++ = *from++;
  for (std::uint32_t* to = __bss_start__; to < __bss_end__;) *to++ = 0;
}

// -nostartfiles leaves no _init to run the static constructors.
inline void run_static_constructors() {
  for (void (**constructor)() = __init_array_start; constructor < __init_array_end; ++constructor) (*constructor)();
}

}  // namespace cdcr::baremetal
