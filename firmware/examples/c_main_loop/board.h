/* What the example needs from its board: a periodic timer and a console. */
#ifndef EXAMPLE_BOARD_H
#define EXAMPLE_BOARD_H

#include <stdint.h>

void board_timer_start(int64_t period_ns);
void board_timer_wait(void); /* until the next period starts */
int64_t board_now_ns(void);  /* monotonic */
void board_print(const char *text);

#endif
