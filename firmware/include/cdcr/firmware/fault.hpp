#pragma once
// The runtime's states and the one list of fault codes it reports (in the
// STATUS frame, FAULT signal; the STATS frame's FAULT_DETAIL refines some,
// see fault_detail.hpp).

#include <cstdint>

namespace cdcr::firmware {

enum class RuntimeState : std::uint8_t {
  boot = 0,      // validating the model image; nothing published yet
  run = 1,       // compensated kinematics (nominal model + GP correction)
  degraded = 2,  // nominal kinematics only: the image is missing or invalid
  fault = 3,     // safe state: input lost (see Runtime for what is held)
};

enum class FaultCode : std::uint8_t {
  none = 0,
  image_missing = 1,           // the model region is empty
  image_invalid = 2,           // parse_image refused it; FAULT_DETAIL = model::ImageStatus
  image_geometry_invalid = 3,  // the image's geometry or segment count is unusable; detail = model::Status
  cable_input_stale = 4,       // no fresh cable frames from every segment within kStaleInputCycles
  cable_frame_malformed = 5,   // last rejected cable frame: wrong DLC, unknown segment, value out of range
  cable_lengths_invalid = 6,   // last cable set the kinematics refused (NaN, impossible differences); detail = model::Status
  target_malformed = 7,        // last target frame refused: wrong DLC, NaN, non-unit quaternion, out of sequence
  target_unreachable = 8,      // last IK request did not converge; setpoints held; detail = model::Status
  can_transmit_failed = 9,     // a frame could not be queued for transmission
  can_filters_refused = 10,    // the controller refused the acceptance filters: the runtime runs and ignores
                               // foreign frames, but every frame on the bus now costs it a receive
  payload_invalid = 11,        // last payload refused (malformed PAYLOAD frame, beyond its range, NaN); the
                               // previous payload stays in use
  homing_malformed = 12,       // last HOMING frame refused (wrong DLC, AT_HOME not 1): the hysteresis state
                               // is unchanged
  // The drives of a hal::Drives backend (CiA 402): the runtime is in FAULT
  // until they are recovered; FAULT_DETAIL is the drive's node id.
  drive_silent = 13,           // a drive stopped answering: at boot, to its configuration, its heartbeat, its position
  drive_fault = 14,            // a drive reported a fault (EMCY, statusword) or left Operation enabled
  drive_refused = 15,          // the drives' configuration was refused (an SDO abort, an invalid configuration,
                               // a setpoint beyond a drive's range)
  drives_command_malformed = 16,  // last DRIVES_COMMAND frame refused (wrong DLC, unknown command)
};

constexpr const char* to_string(RuntimeState state) {
  switch (state) {
    case RuntimeState::boot: return "BOOT";
    case RuntimeState::run: return "RUN";
    case RuntimeState::degraded: return "DEGRADED";
    case RuntimeState::fault: return "FAULT";
  }
  return "UNKNOWN";
}

constexpr const char* to_string(FaultCode code) {
  switch (code) {
    case FaultCode::none: return "none";
    case FaultCode::image_missing: return "model image missing";
    case FaultCode::image_invalid: return "model image invalid";
    case FaultCode::image_geometry_invalid: return "model image geometry invalid";
    case FaultCode::cable_input_stale: return "cable input stale";
    case FaultCode::cable_frame_malformed: return "cable frame malformed";
    case FaultCode::cable_lengths_invalid: return "cable lengths invalid";
    case FaultCode::target_malformed: return "target frame malformed";
    case FaultCode::target_unreachable: return "target unreachable";
    case FaultCode::can_transmit_failed: return "CAN transmit failed";
    case FaultCode::can_filters_refused: return "CAN acceptance filters refused";
    case FaultCode::payload_invalid: return "payload invalid";
    case FaultCode::homing_malformed: return "homing frame malformed";
    case FaultCode::drive_silent: return "drive silent";
    case FaultCode::drive_fault: return "drive fault";
    case FaultCode::drive_refused: return "drive configuration refused";
    case FaultCode::drives_command_malformed: return "drives command malformed";
  }
  return "unknown fault";
}

}  // namespace cdcr::firmware
