#ifndef C_API_CHECK_H
#define C_API_CHECK_H
#include <cdcr/cdcr.h>
#ifdef __cplusplus
extern "C" {
#endif
/* Initialises a runtime with `image` (NULL: none) and `geometry` (NULL: the
 * prototype), feeds `lengths_mm` and steps `steps` times; then reads the
 * status and the pose. 0 on success, else the number of the call that failed. */
int c_api_check_pose(const uint8_t *image, uint32_t image_size, const cdcr_geometry *geometry,
                     const float *lengths_mm, size_t count, int steps, cdcr_pose *pose, cdcr_status *status);
#ifdef __cplusplus
}
#endif
#endif
