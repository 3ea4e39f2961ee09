// Ways a program can go wrong on the target without a debugger attached, each
// turned into a report on the board's console and a distinct exit status.

#include <cstddef>

#include "cdcr/baremetal/console.hpp"

using cdcr::baremetal::console_write;
using cdcr::baremetal::ExitCode;

extern "C" [[noreturn]] void cdcr_assert_failed(const char* expression, const char* file, int line) {
  console_write("ASSERTION FAILED: ");
  console_write(expression);
  console_write(" at ");
  console_write(file);
  console_write(":");
  cdcr::baremetal::console_write_int(line);
  console_write("\n");
  cdcr::baremetal::exit(ExitCode::assertion_failed);
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
  console_write("HEAP USED: operator delete called\n");
  cdcr::baremetal::exit(ExitCode::heap_used);
}
void operator delete(void*) noexcept { heap_used(); }
void operator delete(void*, std::size_t) noexcept { heap_used(); }
void operator delete[](void*) noexcept { heap_used(); }
void operator delete[](void*, std::size_t) noexcept { heap_used(); }
