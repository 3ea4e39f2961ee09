/* The board on QEMU's MPS2 Cortex-M boards: SysTick and semihosting. */
#include <cdcr/cortexm/mps2.h>

#include "board.h"

void board_timer_start(int64_t period_ns) { cdcr_mps2_timer_start(period_ns); }
void board_timer_wait(void) { (void)cdcr_mps2_timer_wait_next(); }
int64_t board_now_ns(void) { return cdcr_mps2_now_ns(); }
void board_print(const char *text) { cdcr_mps2_console_write(text); }
