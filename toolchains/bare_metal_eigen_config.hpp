#pragma once
// Force-included before every C++ translation unit of a bare-metal build
// (arm-none-eabi-common.cmake). Eigen's default eigen_assert is assert(),
// whose newlib implementation formats with fiprintf and so allocates; the
// board's handler reports on its console instead. The bare-metal code
// every board builds on defines cdcr_assert_failed (hal/baremetal/src/traps.cpp).
// NDEBUG removes the checks as Eigen itself would.

extern "C" [[noreturn]] void cdcr_assert_failed(const char* expression, const char* file, int line);

#ifdef NDEBUG
#define eigen_assert(x) ((void)0)
#else
#define eigen_assert(x) ((x) ? (void)0 : cdcr_assert_failed(#x, __FILE__, __LINE__))
#endif
