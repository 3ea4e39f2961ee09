/*
 * cdcr.h: the runtime for board integrators, in C99.
 *
 * One runtime object in storage the caller owns (static, no heap), built with
 * the board's callbacks; then, once per period, feed what the drives report,
 * step, and read what the runtime computed:
 *
 *   static cdcr_runtime runtime;
 *   cdcr_config config = {0};
 *   config.model_image = image;          // the flash image (`cdcr export`); NULL: nominal model
 *   config.model_image_size = image_size;
 *   config.callbacks.now_ns = board_now_ns;
 *   cdcr_init(&runtime, &config);
 *   for (;;) {
 *     board_wait_for_period();
 *     cdcr_set_cable_lengths(&runtime, lengths_mm, 16);   // every segment's cables, in order
 *     cdcr_step(&runtime);
 *     cdcr_get_pose(&runtime, &pose);
 *     if (cdcr_get_setpoints(&runtime, &setpoints) == CDCR_OK) ... // to the drives
 *   }
 *
 * Cable lengths and targets enter the runtime exactly as the CAN frames of
 * the protocol (cdcr/firmware/protocol/messages.hpp) would carry them
 * (lengths in 0.01 mm steps, positions in 0.01 mm, quaternions in Q15), so a
 * board with its own bus and a board on the CAN protocol see the same
 * behaviour. A board on the CAN protocol gives can_send/can_receive instead,
 * or as well.
 *
 * Nothing here allocates or throws; every function returns a cdcr_result.
 * Not thread-safe: call everything for one runtime from one context.
 * Units: millimetres and radians; rotations row-major, quaternions w first.
 */
#ifndef CDCR_CDCR_H
#define CDCR_CDCR_H

#include <stddef.h>
#include <stdint.h>

/* cdcr_callbacks, cdcr_can_frame, cdcr_can_filter: the board's side. */
#include "cdcr/callbacks/callbacks.h"

#ifdef __cplusplus
extern "C" {
#endif

#define CDCR_MAX_SEGMENTS 8
#define CDCR_MAX_CABLES (4 * CDCR_MAX_SEGMENTS)

/* Bytes of cdcr_runtime: enough for every supported target (host, Cortex-M7,
 * Cortex-M4F), checked when the library is compiled;
 * cdcr_runtime_storage_size() says how much this build uses. */
#define CDCR_RUNTIME_STORAGE_BYTES 20480u

/* Opaque: the caller provides the storage, typically as a static variable. */
typedef struct cdcr_runtime {
  union {
    int64_t align_integer;
    double align_double;
    void *align_pointer;
    unsigned char bytes[CDCR_RUNTIME_STORAGE_BYTES];
  } storage;
} cdcr_runtime;

typedef enum cdcr_result {
  CDCR_OK = 0,
  CDCR_ERROR_NULL_ARGUMENT = 1,    /* a required pointer is NULL */
  CDCR_ERROR_NOT_INITIALIZED = 2,  /* cdcr_init() has not succeeded on this runtime */
  CDCR_ERROR_INVALID_ARGUMENT = 3, /* segment index or count, geometry, mode, quaternion not of unit norm */
  CDCR_ERROR_OUT_OF_RANGE = 4,     /* a value the protocol cannot carry: NaN, infinity, a cable length
                                      outside 0.01..655.34 mm, a position beyond +-21,474 m */
  CDCR_ERROR_QUEUE_FULL = 5,       /* too many inputs before the next cdcr_step() */
  CDCR_ERROR_NO_DATA = 6,          /* nothing to read yet: no pose, or no setpoints */
  CDCR_ERROR_NOT_APPLICABLE = 7    /* not with this configuration: cable lengths given while CiA 402 drives
                                      report them, drives recovered where there are none */
} cdcr_result;

/* The runtime's states (firmware/include/cdcr/firmware/fault.hpp). */
typedef enum cdcr_state {
  CDCR_STATE_BOOT = 0,     /* before the first cdcr_init() completes */
  CDCR_STATE_RUN = 1,      /* compensated kinematics: nominal model and the image's GP correction */
  CDCR_STATE_DEGRADED = 2, /* nominal kinematics: no image, or an invalid one (see boot_fault) */
  CDCR_STATE_FAULT = 3     /* cable input stale: no pose, no setpoints, targets refused */
} cdcr_state;

typedef enum cdcr_fault {
  CDCR_FAULT_NONE = 0,
  CDCR_FAULT_IMAGE_MISSING = 1,
  CDCR_FAULT_IMAGE_INVALID = 2,          /* fault_detail: the image parser's status */
  CDCR_FAULT_IMAGE_GEOMETRY_INVALID = 3, /* fault_detail: the model's status */
  CDCR_FAULT_CABLE_INPUT_STALE = 4,      /* a segment without fresh lengths for more than 10 steps */
  CDCR_FAULT_CABLE_FRAME_MALFORMED = 5,
  CDCR_FAULT_CABLE_LENGTHS_INVALID = 6,  /* lengths the kinematics refused; fault_detail: the model's status */
  CDCR_FAULT_TARGET_MALFORMED = 7,
  CDCR_FAULT_TARGET_UNREACHABLE = 8,     /* fault_detail: the model's status */
  CDCR_FAULT_CAN_TRANSMIT_FAILED = 9,    /* can_send returned non-zero */
  CDCR_FAULT_CAN_FILTERS_REFUSED = 10,   /* can_receive given without can_set_filters, or it refused */
  CDCR_FAULT_PAYLOAD_INVALID = 11,       /* a PAYLOAD frame beyond 0..50 kg: the previous payload stays */
  CDCR_FAULT_HOMING_MALFORMED = 12,      /* a HOMING frame that does not decode: the hysteresis state stays */
  CDCR_FAULT_DRIVE_SILENT = 13,          /* CiA 402 drives: one stopped answering; fault_detail: its node id */
  CDCR_FAULT_DRIVE_FAULT = 14,           /* one reported a fault or left Operation enabled; fault_detail: node */
  CDCR_FAULT_DRIVE_REFUSED = 15,         /* their configuration was refused; fault_detail: node (0: as given) */
  CDCR_FAULT_DRIVES_COMMAND_MALFORMED = 16 /* a DRIVES_COMMAND frame was refused (CAN protocol only) */
} cdcr_fault;

/* How the last target ended (the IK_REPORT frame's OUTCOME). */
typedef enum cdcr_ik_outcome {
  CDCR_IK_CONVERGED = 0,          /* setpoints published */
  CDCR_IK_UNREACHABLE = 1,        /* setpoints held */
  CDCR_IK_REJECTED_MALFORMED = 2,
  CDCR_IK_REJECTED_STATE = 3,     /* the runtime was in FAULT */
  CDCR_IK_SUPERSEDED = 4,         /* a newer target replaced it */
  CDCR_IK_ABORTED_FAULT = 5,      /* the runtime entered FAULT while solving */
  CDCR_IK_IN_PROGRESS = 6,        /* periodic report while solving */
  CDCR_IK_REFUSED_EXTRAPOLATING = 7, /* the solution extrapolates and the target refused that; setpoints held */
  CDCR_IK_NONE = 15               /* no target received yet (never on the bus) */
} cdcr_ik_outcome;

typedef enum cdcr_target_mode {
  CDCR_TARGET_POSITION = 0, /* tip position only */
  CDCR_TARGET_POSE = 1      /* position and orientation */
} cdcr_target_mode;

/* The robot's design geometry, the same for every segment. Used when there
 * is no valid image (DEGRADED); an image carries the geometry it was trained
 * on (and its cables' anchor angles). All zero: the paper's prototype (4
 * segments, L = 120 mm, r = 67 mm, theta_max = pi/2, four cables at 90
 * degrees). */
typedef struct cdcr_geometry {
  int segment_count; /* 1..CDCR_MAX_SEGMENTS */
  float backbone_length_mm;
  float anchor_radius_mm;
  float theta_max_rad;
  int cables_per_segment; /* 0 or 4: four cables at 90 degrees; 3: three at 120 degrees, cable 1 on the x axis */
} cdcr_geometry;

/* CiA 402 drives over CANopen, one per cable (firmware/canopen): the runtime
 * is their NMT master and SYNC producer, configures them by SDO, enables
 * them, takes the cable lengths from their positions every step and sends
 * them the setpoints, through the callbacks drives_can_send and
 * drives_can_receive. Cable length = position / counts_per_mm +
 * homing_offset_mm. A drive's fault is CDCR_FAULT_DRIVE_SILENT, _FAULT or
 * _REFUSED with its node id in fault_detail, until cdcr_recover_drives(). */
#define CDCR_MAX_DRIVE_BUSES 4

typedef struct cdcr_cia402_drive {
  int bus;                /* 0..bus_count - 1, the index the drives_can callbacks get */
  int node;               /* CANopen node id, 1..127, one drive per node on a bus */
  float counts_per_mm;    /* the drive's position units per mm of cable; negative where they fall as it lengthens */
  float homing_offset_mm; /* the cable's length at position 0 (after the drive's homing) */
} cdcr_cia402_drive;

typedef struct cdcr_cia402_config {
  int drive_count; /* one per cable, cable 0 first: the image's cable count */
  int bus_count;   /* 1..CDCR_MAX_DRIVE_BUSES */
  cdcr_cia402_drive drives[CDCR_MAX_CABLES];
  /* 0 takes the default given. The cycle period (0x1006) is cdcr_config.period_ns. */
  uint32_t sync_window_us;         /* 0x1007, at most the period; 0: half the period */
  uint32_t heartbeat_ms;           /* each drive's heartbeat producer time; 0: 50 */
  uint32_t heartbeat_periods_lost; /* periods without a heartbeat before a drive is lost; 0: 3 */
  uint32_t stale_cycles;           /* steps without a position before it is stale; 0: 10 */
  uint32_t boot_timeout_ms;        /* 0: 2000 */
  uint32_t sdo_timeout_ms;         /* 0: 100 */
  uint32_t enable_timeout_ms;      /* 0: 1000 */
  float max_speed_mm_per_s;        /* how fast a drive's target moves to its setpoint; 0: 20 */
} cdcr_cia402_config;

typedef struct cdcr_config {
  const uint8_t *model_image; /* the flash image in place (not copied); NULL: nominal kinematics */
  uint32_t model_image_size;
  cdcr_geometry fallback_geometry;
  /* The period the caller steps at: release k is at the first step's time
   * plus k periods, which gives jitter and overrun counts. 0: none kept. */
  int64_t period_ns;
  cdcr_callbacks callbacks;
  /* Where the protocol's 128 identifiers start on the board's bus: a
   * multiple of 8 from 0x008 to 0x780, for a bus shared with other traffic
   * (CANopen's 0x100 is TIME). 0: the protocol's own base, 0x100. The
   * callbacks then send and receive frames at the moved identifiers, and set
   * the filters there. */
  uint32_t can_id_base;
  /* NULL: the board gives the cable lengths (cdcr_set_cable_lengths) and
   * sends the setpoints to its drives itself. Otherwise the runtime runs
   * these CiA 402 drives (copied at init; period_ns must be set, whole
   * microseconds). */
  const cdcr_cia402_config *cia402_drives;
} cdcr_config;

typedef struct cdcr_target {
  float position_mm[3];
  float quaternion[4]; /* w, x, y, z; used in CDCR_TARGET_POSE mode, within 1e-2 of unit norm */
  cdcr_target_mode mode;
  int tracking;     /* non-zero: one of a stream along a path (TRACKING) */
  uint8_t sequence; /* echoed in cdcr_status.ik_sequence */
  /* non-zero: refuse a solution where the model extrapolates
   * (REFUSE_EXTRAPOLATING): CDCR_IK_REFUSED_EXTRAPOLATING, setpoints held */
  int refuse_extrapolating;
} cdcr_target;

typedef struct cdcr_pose {
  float position_mm[3];
  float rotation[9];   /* row-major */
  float quaternion[4]; /* w, x, y, z with w >= 0 */
  float joints[2 * CDCR_MAX_SEGMENTS]; /* alpha_1, theta_1, alpha_2, ... (rad) */
  int segment_count;
  int compensated;     /* 1 in RUN (GP-corrected), 0 in DEGRADED (nominal) */
  uint32_t count;      /* poses computed so far: changes when this one is new */
  int extrapolating;   /* 1: the model extrapolates at this pose (its variance; before image 2.6 also its input range) */
  /* The radii around a recent compensated pose (a few cycles old) that hold
   * the measured pose with 95 % probability; 0 until the first is computed,
   * and without a variance block in the image. */
  float r95_mm;
  float r95_deg;
} cdcr_pose;

typedef struct cdcr_setpoints {
  float lengths_mm[CDCR_MAX_CABLES]; /* l1_1, l1_2, ..., l2_1, ...: what the drives should hold */
  int cable_count;                   /* every segment's cables (cdcr_get_segment_cables) */
  uint32_t count;                    /* setpoints published so far: changes when these are new */
} cdcr_setpoints;

typedef struct cdcr_status {
  cdcr_state state;
  cdcr_fault fault;       /* what the STATUS frame reports now */
  uint8_t fault_detail;   /* what the STATS frame reports with it */
  cdcr_fault boot_fault;  /* why the image was not used (CDCR_FAULT_NONE in RUN) */
  /* The last target. */
  cdcr_ik_outcome ik_outcome;
  uint8_t ik_sequence;
  int ik_running; /* a target is being solved */
  int ik_iterations;
  int ik_cycles;
  float ik_position_error_mm;
  float ik_orientation_error_rad;
  /* Counters since init. */
  uint32_t cycles;
  uint32_t overruns;
  uint32_t rejected_frames;
  uint32_t stale_events;
  uint32_t targets_received;
  int64_t execution_max_ns;
  int64_t execution_mean_ns;
  int64_t jitter_max_ns;
  /* 1: the model image has a hysteresis block and the cables' hysteresis
   * state is not yet known (since init, until every cable has travelled far
   * enough one way, or cdcr_homing()): r95 includes it. 0 without a block. */
  int hysteresis_unknown;
} cdcr_status;

/* Bytes of cdcr_runtime this build uses (at most CDCR_RUNTIME_STORAGE_BYTES). */
size_t cdcr_runtime_storage_size(void);

/* BOOT: validates the image and chooses RUN or DEGRADED. CDCR_OK also when
 * the image is refused (the state says DEGRADED, the status why); an error
 * only for arguments it cannot work with. May be called again to restart. */
cdcr_result cdcr_init(cdcr_runtime *runtime, const cdcr_config *config);

/* One cycle: takes the inputs given since the last step (and what can_receive
 * has), updates the pose, continues a target's inverse kinematics within the
 * cycle's budget, publishes. */
cdcr_result cdcr_step(cdcr_runtime *runtime);

/* The drives' cable lengths: all of them, segment by segment (count = the
 * sum of the segments' cables, 4 x segments for the paper's robot), or one
 * segment's (3 or 4 values: cdcr_get_segment_cables). Take effect at the
 * next cdcr_step(); a segment that is not fed for more than 10 steps takes
 * the runtime to FAULT. */
cdcr_result cdcr_set_cable_lengths(cdcr_runtime *runtime, const float *lengths_mm, size_t count);
cdcr_result cdcr_set_segment_cable_lengths(cdcr_runtime *runtime, int segment, const float *lengths_mm);

/* How many cables drive a segment (3 or 4), from the image's geometry, or
 * the fallback's without a valid image. */
cdcr_result cdcr_get_segment_cables(const cdcr_runtime *runtime, int segment, int *cables);

/* The tip payload in kg (0 to 50), for a model image with a payload input:
 * the pose and inverse kinematics use it from the next cdcr_step(); until
 * one is set, the image's default. CDCR_ERROR_OUT_OF_RANGE for NaN or a
 * value outside 0..50 kg, and nothing changes. A model without a payload
 * input ignores it. */
cdcr_result cdcr_set_payload(cdcr_runtime *runtime, float payload_kg);

/* The robot has just completed the homing move (every segment bent 0.1 rad
 * towards alpha = 45 deg, then back straight) and is at home: from the next
 * cdcr_step() the cables' hysteresis state is the image's homing state, and
 * the cable lengths given next are its position (the HOMING frame's
 * meaning). Changes nothing with an image without a hysteresis block. */
cdcr_result cdcr_homing(cdcr_runtime *runtime);
/* After a CiA 402 drive's fault: reset and re-enable every drive; the
 * runtime leaves the fault once all are enabled again. While they are fine
 * it changes nothing. CDCR_ERROR_NOT_APPLICABLE without cia402_drives. */
cdcr_result cdcr_recover_drives(cdcr_runtime *runtime);

/* A target for the tip; the runtime solves it over the next steps and
 * publishes setpoints when it converges (see cdcr_status.ik_outcome). */
cdcr_result cdcr_set_target(cdcr_runtime *runtime, const cdcr_target *target);

/* The latest pose: CDCR_ERROR_NO_DATA before the first, and in FAULT (the
 * runtime publishes no pose then). */
cdcr_result cdcr_get_pose(const cdcr_runtime *runtime, cdcr_pose *pose);
/* The latest setpoints: CDCR_ERROR_NO_DATA before the first converged target. */
cdcr_result cdcr_get_setpoints(const cdcr_runtime *runtime, cdcr_setpoints *setpoints);
cdcr_result cdcr_get_status(const cdcr_runtime *runtime, cdcr_status *status);

/* Names for logs; never NULL. */
const char *cdcr_result_name(cdcr_result result);
const char *cdcr_state_name(cdcr_state state);
const char *cdcr_fault_name(cdcr_fault fault);

#ifdef __cplusplus
}
#endif

#endif /* CDCR_CDCR_H */
