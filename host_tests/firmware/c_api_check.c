/* The C API from C: compiled as C99 with -Wpedantic -Werror, so the header
 * must be C, and driven from c_api_test.cpp. */
#include <cdcr/cdcr.h>

#include "c_api_check.h"

static cdcr_runtime runtime;

int c_api_check_pose(const uint8_t *image, uint32_t image_size, const cdcr_geometry *geometry,
                     const float *lengths_mm, size_t count, int steps, cdcr_pose *pose, cdcr_status *status) {
  cdcr_config config = {0};
  int step;
  config.model_image = image;
  config.model_image_size = image_size;
  if (geometry != NULL) config.fallback_geometry = *geometry;
  if (cdcr_init(&runtime, &config) != CDCR_OK) return 1;
  for (step = 0; step < steps; ++step) {
    if (cdcr_set_cable_lengths(&runtime, lengths_mm, count) != CDCR_OK) return 2;
    if (cdcr_step(&runtime) != CDCR_OK) return 3;
  }
  if (cdcr_get_status(&runtime, status) != CDCR_OK) return 4;
  if (cdcr_get_pose(&runtime, pose) != CDCR_OK) return 5;
  return 0;
}
