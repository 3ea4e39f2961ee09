// Ways a program can go wrong on the target without a debugger attached, each
// turned into a report on the UART and a distinct exit status.

#include <cstddef>

#include "cdcr/zynqmp/console.hpp"

using cdcr::zynqmp::ExitCode;

extern "C" [[noreturn]] void cdcr_assert_failed(const char* expression, const char* file, int line) {
  cdcr::zynqmp::console_write("ASSERTION FAILED: ");
  cdcr::zynqmp::console_write(expression);
  cdcr::zynqmp::console_write(" at ");
  cdcr::zynqmp::console_write(file);
  cdcr::zynqmp::console_write(":");
  cdcr::zynqmp::console_write_int(line);
  cdcr::zynqmp::console_write("\n");
  cdcr::zynqmp::exit(ExitCode::assertion_failed);
}

// newlib's assert() calls this; its own version formats with fiprintf, which
// allocates.
extern "C" [[noreturn]] void __assert_func(const char* file, int line, const char* /*function*/,
                                           const char* expression) {
  cdcr_assert_failed(expression, file, line);
}

// A virtual destructor references operator delete even when nothing is ever
// deleted; the library's version would pull in free() and with it the heap.
// No operator new is defined, so any allocation still fails the link.
[[noreturn]] static void heap_used() {
  cdcr::zynqmp::console_write("HEAP USED: operator delete called\n");
  cdcr::zynqmp::exit(ExitCode::heap_used);
}
void operator delete(void*) noexcept { heap_used(); }
void operator delete(void*, std::size_t) noexcept { heap_used(); }
void operator delete[](void*) noexcept { heap_used(); }
void operator delete[](void*, std::size_t) noexcept { heap_used(); }
