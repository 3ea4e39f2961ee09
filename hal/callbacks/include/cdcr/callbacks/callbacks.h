/*
 * callbacks.h: the board's side of the C API (cdcr/cdcr.h), in C99: the
 * functions a board gives the runtime for its clock, console and CAN bus.
 * The HAL backend in callback_hal.hpp turns them into the runtime's HAL.
 */
#ifndef CDCR_CALLBACKS_CALLBACKS_H
#define CDCR_CALLBACKS_CALLBACKS_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* A classic CAN frame, for boards that run the CAN protocol through the runtime. */
typedef struct cdcr_can_frame {
  uint32_t id; /* 11-bit identifier */
  uint8_t dlc; /* 0..8 */
  uint8_t data[8];
} cdcr_can_frame;

/* Accept a frame when (frame.id & mask) == (id & mask). */
typedef struct cdcr_can_filter {
  uint32_t id;
  uint32_t mask;
} cdcr_can_filter;

/* The board's side. Every callback is optional and gets `user` back. */
typedef struct cdcr_callbacks {
  void *user;
  /* Monotonic nanoseconds. Without it the cycle statistics read 0. */
  int64_t (*now_ns)(void *user);
  /* One log line, NUL-terminated, without a newline. Without it lines are dropped. */
  void (*console_write_line)(void *user, const char *line);
  /* CAN, for boards that carry the protocol on a bus (all NULL otherwise):
   * can_send returns 0 when the frame is queued; can_receive returns 1 and
   * fills *frame when one was waiting, 0 when none; can_set_filters returns
   * 1 when the controller holds the filters, 0 when it refuses them. */
  int (*can_send)(void *user, const cdcr_can_frame *frame);
  int (*can_receive)(void *user, cdcr_can_frame *frame);
  int (*can_set_filters)(void *user, const cdcr_can_filter *filters, size_t count);
  /* The CiA 402 drives' buses (cdcr_config.cia402_drives; NULL otherwise),
   * bus 0 to 3 as the drives' configuration numbers them, which may be the
   * protocol's bus too: as can_send and can_receive, for that bus. Every
   * frame on a drives' bus goes to the runtime, which takes what its drives
   * send (no filters are set there). */
  int (*drives_can_send)(void *user, int bus, const cdcr_can_frame *frame);
  int (*drives_can_receive)(void *user, int bus, cdcr_can_frame *frame);
} cdcr_callbacks;

#ifdef __cplusplus
}
#endif

#endif /* CDCR_CALLBACKS_CALLBACKS_H */
