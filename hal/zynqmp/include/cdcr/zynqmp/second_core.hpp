#pragma once
// The RPU's second Cortex-R5F core, in split mode: a program that defines
// cdcr_zynqmp_second_core_main and links cdcr::zynqmp_second_core (the
// linker script then reserves the second core's stacks) runs it there,
// beside its main on the first core. Both cores start at the ELF's entry
// (vectors.S gives each its own stacks); the second waits in the start-up
// until the first has initialised .data, .bss and the static constructors
// and calls release_second_core(). In other programs the second core parks
// at reset (and QEMU leaves it powered off unless run_r5f.cmake is told
// SECOND_CORE).
//
// What the cores share is the program's code and memory; words that both
// write belong in .core_shared (CDCR_ZYNQMP_CORE_SHARED), 32 bytes that no
// data cache holds, since the two cores' caches are not coherent. On
// silicon the second core is released from reset by the first (or by the
// platform firmware) through the RPU's reset control, which QEMU 7.2 does
// not model: the runner powers both on.

#include <cstdint>

// A variable both cores read and write: `CDCR_ZYNQMP_CORE_SHARED volatile
// std::uint32_t done;`. Not cleared by the start-up (the second core may read
// the release word in it before the first core's start-up runs): the first
// core sets the program's words before release_second_core().
#define CDCR_ZYNQMP_CORE_SHARED __attribute__((section(".core_shared")))

extern "C" {
// Defined by the program that uses the second core; runs there after
// release_second_core(). Returning parks the core.
void cdcr_zynqmp_second_core_main();
}

namespace cdcr::zynqmp {

// From the first core, once its start-up and whatever the second core's
// program needs first are done: cleans the first core's data cache (what
// it wrote reaches the DDR the second core reads) and lets the second
// core's start-up go on. In
// a program linked without the second core's stacks, reports that and
// exits with ExitCode::failure.
void release_second_core();

// This core has nothing to do for now: the hint a spinning core gives its
// sibling. Under QEMU 7.2's TCG, which runs every core in turn on one host
// thread, YIELD ends this core's turn at once, so the other core runs
// instead of waiting for this one's time slice to run out.
inline void yield_to_other_core() { asm volatile("yield" ::: "memory"); }

}  // namespace cdcr::zynqmp
