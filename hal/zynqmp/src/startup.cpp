// The C++ half of the R5F start-up: vectors.S has set the exception mode
// stacks, enabled the FPU and the instruction cache, and calls
// cdcr_zynqmp_start in System mode.

#include <cstdint>

#include <cdcr/baremetal/startup.hpp>

#include "cdcr/zynqmp/console.hpp"
#include "cdcr/zynqmp/second_core.hpp"

extern "C" {
// ISO C++ forbids calling main, so the start-up reaches the program's main
// through another name for the same symbol.
int cdcr_zynqmp_application_main() __asm__("main");
[[noreturn]] void cdcr_zynqmp_start();
[[noreturn]] void cdcr_zynqmp_second_core_start();
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

// The word the first core sets when the second may run; a value unlikely
// to be left in RAM by anything else.
constexpr std::uint32_t kSecondCoreReleased = 0x52355F31u;  // "R5_1"
CDCR_ZYNQMP_CORE_SHARED volatile std::uint32_t second_core_release;

}  // namespace

// The linker script's size of the second core's stacks: 0 in a program
// linked without them, whose second core parked at reset (vectors.S).
extern "C" char __core_stacks_size__[];

namespace {

// Everything this core wrote through its data cache (.data, .bss, the
// static constructors' objects) out to the DDR, where the second core reads
// it: the two cores' caches are not coherent. The level 1 data cache set by
// set and way over the geometry CCSIDR reports, as vectors.S invalidates it.
void clean_data_cache() {
  asm volatile("mcr p15, 2, %0, c0, c0, 0\n\tisb" ::"r"(0u));  // CSSELR: level 1 data cache
  std::uint32_t geometry;
  asm volatile("mrc p15, 1, %0, c0, c0, 0" : "=r"(geometry));  // CCSIDR
  const std::uint32_t set_shift = (geometry & 7u) + 4u;       // log2(line bytes)
  const std::uint32_t last_way = (geometry >> 3) & 0x3FFu;
  const std::uint32_t last_set = (geometry >> 13) & 0x7FFFu;
  const std::uint32_t way_shift = last_way == 0 ? 0u : static_cast<std::uint32_t>(__builtin_clz(last_way));
  for (std::uint32_t way = 0; way <= last_way; ++way) {
    for (std::uint32_t set = 0; set <= last_set; ++set) {
      const std::uint32_t set_way = (way << way_shift) | (set << set_shift);
      asm volatile("mcr p15, 0, %0, c7, c10, 2" ::"r"(set_way) : "memory");  // DCCSW
    }
  }
  asm volatile("dsb" ::: "memory");
}

}  // namespace

void cdcr::zynqmp::release_second_core() {
  // The symbol's address is the size; the compiler may not take an
  // object's address for never null.
  std::uintptr_t second_core_stacks = reinterpret_cast<std::uintptr_t>(__core_stacks_size__);
  asm("" : "+r"(second_core_stacks));
  if (second_core_stacks == 0) {
    console_write("second core: the program has no stacks for it (link cdcr::zynqmp_second_core)\n");
    exit(ExitCode::failure);
  }
  clean_data_cache();
  second_core_release = kSecondCoreReleased;
  // The write before the event that wakes the second core from its WFE.
  asm volatile("dsb\n\tsev" ::: "memory");
}

// A program without a second core's part leaves the core parked.
extern "C" __attribute__((weak)) void cdcr_zynqmp_second_core_main() {}

// vectors.S has set this core's stacks, FPU, MPU and caches. The first
// core's start-up initialises what both share; until it releases this core,
// WFE (which QEMU 7.2 takes as a yield to the other core).
extern "C" [[noreturn]] void cdcr_zynqmp_second_core_start() {
  while (second_core_release != kSecondCoreReleased) asm volatile("wfe" ::: "memory");
  asm volatile("dmb" ::: "memory");
  cdcr_zynqmp_second_core_main();
  for (;;) asm volatile("wfi");
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
