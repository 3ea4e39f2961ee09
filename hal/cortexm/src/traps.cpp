// Ways a program can go wrong on the target without a debugger attached, each
// turned into a report on the console and a distinct exit status.

#include <cstddef>

#include "cdcr/cortexm/semihosting.hpp"

using cdcr::cortexm::ExitCode;

extern "C" [[noreturn]] void cdcr_assert_failed(const char* expression, const char* file, int line) {
  cdcr::cortexm::console_write("ASSERTION FAILED: ");
  cdcr::cortexm::console_write(expression);
  cdcr::cortexm::console_write(" at ");
  cdcr::cortexm::console_write(file);
  cdcr::cortexm::console_write(":");
  cdcr::cortexm::console_write_int(line);
  cdcr::cortexm::console_write("\n");
  cdcr::cortexm::exit(ExitCode::assertion_failed);
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
  cdcr::cortexm::console_write("HEAP USED: operator delete called\n");
  cdcr::cortexm::exit(ExitCode::heap_used);
}
void operator delete(void*) noexcept { heap_used(); }
void operator delete(void*, std::size_t) noexcept { heap_used(); }
void operator delete[](void*) noexcept { heap_used(); }
void operator delete[](void*, std::size_t) noexcept { heap_used(); }
