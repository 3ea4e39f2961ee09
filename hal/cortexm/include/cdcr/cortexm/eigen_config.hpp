#pragma once
// Force-included before every translation unit of a Cortex-M build. Eigen's
// default eigen_assert is assert(), whose newlib implementation formats with
// fiprintf and so allocates; the handler reports over semihosting instead.
// NDEBUG removes the checks as Eigen itself would.

#ifdef __cplusplus
extern "C" [[noreturn]] void cdcr_cortexm_assert_failed(const char* expression, const char* file, int line);
#else
_Noreturn void cdcr_cortexm_assert_failed(const char* expression, const char* file, int line);
#endif

#ifdef NDEBUG
#define eigen_assert(x) ((void)0)
#else
#define eigen_assert(x) ((x) ? (void)0 : cdcr_cortexm_assert_failed(#x, __FILE__, __LINE__))
#endif
