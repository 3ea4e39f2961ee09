/*
 * QEMU's MPS2 boards (mps2-an500 Cortex-M7, mps2-an386 Cortex-M4F) for C
 * programs: console output through semihosting and a periodic timer on
 * SysTick at the boards' 25 MHz core clock. Link cdcr::cortexm (startup,
 * linker script) and cdcr::mps2; the startup code calls main() and exits
 * QEMU with its return value.
 */
#ifndef CDCR_CORTEXM_MPS2_H
#define CDCR_CORTEXM_MPS2_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Writes text as it is (no newline added). */
void cdcr_mps2_console_write(const char *text);

/* Starts releases every period_ns; the first is one period from now. */
void cdcr_mps2_timer_start(int64_t period_ns);
/* Sleeps until the next release and returns its time in ns since the start. */
int64_t cdcr_mps2_timer_wait_next(void);
/* Nanoseconds since cdcr_mps2_timer_start(). */
int64_t cdcr_mps2_now_ns(void);

#ifdef __cplusplus
}
#endif

#endif /* CDCR_CORTEXM_MPS2_H */
