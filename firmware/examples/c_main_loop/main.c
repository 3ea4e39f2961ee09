/*
 * A bare main loop around the cdcr runtime, in C.
 *
 * A timer releases one step per millisecond. A bus carries the drives'
 * cable lengths in and the runtime's setpoints out; here it is an in-memory
 * stand-in whose drives reach each setpoint at once. Each period: read the
 * lengths from the bus, feed them, step, send new setpoints, and now and
 * then print the tip pose. After a while the program gives the tip a target
 * and checks that the robot got there.
 */
#include <cdcr/cdcr.h>

#include "board.h"

#ifdef EXAMPLE_HAS_MODEL_IMAGE
/* From `cdcr export --format c`. */
extern const uint8_t cdcr_model_image[];
extern const uint32_t cdcr_model_image_size;
#endif

#define PERIOD_NS 1000000 /* 1 kHz */
#define STEPS 400
#define TARGET_AT_STEP 50

/* ---- The bus: the drives of a 4-segment robot, straight at start. ---- */

typedef struct bus {
  float lengths_mm[CDCR_MAX_CABLES];
  int cable_count;
} bus;

static void bus_init(bus *b, int cable_count, float straight_length_mm) {
  int i;
  b->cable_count = cable_count;
  for (i = 0; i < cable_count; ++i) b->lengths_mm[i] = straight_length_mm;
}

static void bus_send_setpoints(bus *b, const cdcr_setpoints *setpoints) {
  int i;
  for (i = 0; i < setpoints->cable_count; ++i) b->lengths_mm[i] = setpoints->lengths_mm[i];
}

/* ---- Printing without printf (newlib's allocates on a board). ---- */

static char *put_text(char *out, const char *text) {
  while (*text != '\0') *out++ = *text++;
  *out = '\0';
  return out;
}

/* A decimal number; with a point before the last `decimals` digits. */
static char *put_number(char *out, long value, int decimals) {
  char digits[16];
  int count = 0;
  if (value < 0) {
    *out++ = '-';
    value = -value;
  }
  do {
    digits[count++] = (char)('0' + value % 10);
    value /= 10;
    if (count == decimals) digits[count++] = '.';
  } while (value != 0 || count <= (decimals > 0 ? decimals + 1 : 0));
  while (count > 0) *out++ = digits[--count];
  *out = '\0';
  return out;
}

static char *put_mm(char *out, float value_mm) { /* to the micrometre */
  return put_number(out, (long)(value_mm * 1000.0f + (value_mm < 0 ? -0.5f : 0.5f)), 3);
}

static void print_pose(int step, const cdcr_pose *pose) {
  char line[128];
  char *out = line;
  out = put_text(out, "step ");
  out = put_number(out, step, 0);
  out = put_text(out, ": tip x ");
  out = put_mm(out, pose->position_mm[0]);
  out = put_text(out, " y ");
  out = put_mm(out, pose->position_mm[1]);
  out = put_text(out, " z ");
  out = put_mm(out, pose->position_mm[2]);
  out = put_text(out, pose->compensated ? " mm (compensated)\n" : " mm (nominal)\n");
  board_print(line);
}

static void console_line(void *user, const char *line) {
  (void)user;
  board_print("runtime: ");
  board_print(line);
  board_print("\n");
}

static int64_t now_ns(void *user) {
  (void)user;
  return board_now_ns();
}

/* ---- The program. ---- */

static cdcr_runtime runtime; /* the runtime's whole memory */

int main(void) {
  cdcr_config config = {0}; /* fallback geometry all zero: the paper's prototype */
  cdcr_target target = {{30.0f, -20.0f, 470.0f}, {1, 0, 0, 0}, CDCR_TARGET_POSITION, 0, 1, 0};
  cdcr_status status;
  cdcr_pose pose;
  cdcr_setpoints setpoints;
  uint32_t setpoints_seen = 0;
  bus drives;
  int step;
  float dx, dy, dz;

#ifdef EXAMPLE_HAS_MODEL_IMAGE
  config.model_image = cdcr_model_image;
  config.model_image_size = cdcr_model_image_size;
#endif
  config.period_ns = PERIOD_NS;
  config.callbacks.now_ns = now_ns;
  config.callbacks.console_write_line = console_line;
  if (cdcr_init(&runtime, &config) != CDCR_OK) return 1;
  cdcr_get_status(&runtime, &status);
  board_print("state ");
  board_print(cdcr_state_name(status.state));
  board_print("\n");

  bus_init(&drives, 16, 120.0f); /* 4 segments, straight: every cable as long as the backbone */
  board_timer_start(PERIOD_NS);
  for (step = 1; step <= STEPS; ++step) {
    board_timer_wait();
    cdcr_set_cable_lengths(&runtime, drives.lengths_mm, (size_t)drives.cable_count);
    if (step == TARGET_AT_STEP) cdcr_set_target(&runtime, &target);
    cdcr_step(&runtime);

    if (cdcr_get_setpoints(&runtime, &setpoints) == CDCR_OK && setpoints.count != setpoints_seen) {
      setpoints_seen = setpoints.count;
      bus_send_setpoints(&drives, &setpoints);
    }
    if (step % 100 == 0 && cdcr_get_pose(&runtime, &pose) == CDCR_OK) print_pose(step, &pose);
  }

  /* The target was reached when the runtime says so and the pose it now
   * computes from the drives' lengths is on it. */
  cdcr_get_status(&runtime, &status);
  if (cdcr_get_pose(&runtime, &pose) != CDCR_OK || status.ik_outcome != CDCR_IK_CONVERGED) {
    board_print("FAIL: target not reached\n");
    return 1;
  }
  dx = pose.position_mm[0] - target.position_mm[0];
  dy = pose.position_mm[1] - target.position_mm[1];
  dz = pose.position_mm[2] - target.position_mm[2];
  if (dx * dx + dy * dy + dz * dz > 0.1f * 0.1f) {
    board_print("FAIL: the tip is off the target\n");
    return 1;
  }
  board_print("PASS\n");
  return 0;
}
