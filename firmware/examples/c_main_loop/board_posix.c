/* The board on a POSIX host: CLOCK_MONOTONIC, absolute sleeps, stdout. */
#define _POSIX_C_SOURCE 200112L
#include <stdio.h>
#include <time.h>

#include "board.h"

static struct timespec next_release;
static int64_t period;

int64_t board_now_ns(void) {
  struct timespec now;
  clock_gettime(CLOCK_MONOTONIC, &now);
  return (int64_t)now.tv_sec * 1000000000 + now.tv_nsec;
}

void board_timer_start(int64_t period_ns) {
  period = period_ns;
  clock_gettime(CLOCK_MONOTONIC, &next_release);
}

void board_timer_wait(void) {
  next_release.tv_nsec += (long)period;
  while (next_release.tv_nsec >= 1000000000L) {
    next_release.tv_nsec -= 1000000000L;
    next_release.tv_sec += 1;
  }
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next_release, NULL) != 0) {
  }
}

void board_print(const char *text) { fputs(text, stdout); }
