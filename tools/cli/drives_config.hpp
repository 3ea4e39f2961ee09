#pragma once
// The CiA 402 drives' configuration file (--drives-config), JSON:
//
//   {
//     "buses": ["can1", "can2"],          // SocketCAN interfaces, bus 0, 1, ...
//     "heartbeat_ms": 50,                 // each drive's heartbeat producer time
//     "heartbeat_periods_lost": 3,        // periods without one before the drive is lost
//     "stale_cycles": 10,                 // cycles without a position before it is stale
//     "sync_window_us": 500,              // 0x1007; at most the cycle period
//     "boot_timeout_ms": 2000, "sdo_timeout_ms": 100, "enable_timeout_ms": 1000,
//     "max_speed_mm_per_s": 20,           // how fast a target moves toward its setpoint
//     "drives": [                         // one per cable, cable 0 first
//       {"cable": 0, "bus": 0, "node": 1, "counts_per_mm": 1000, "direction": 1, "homing_offset_mm": 100.0},
//       ...
//     ]
//   }
//
// Cable length = position / (counts_per_mm * direction) + homing_offset_mm:
// homing_offset_mm is the cable's length where the drive's position is 0
// (after its homing), direction -1 for a drive whose counts fall as the
// cable lengthens. Everything but "buses" and "drives" has the default
// shown. A file that does not hold exactly this is refused with one line
// naming the field.

#include <string>
#include <vector>

#include <cdcr/firmware/canopen/drive_manager.hpp>

namespace cdcr::cli {

struct DrivesConfig {
  std::vector<std::string> buses;
  firmware::canopen::DriveManagerConfig manager;
};

// `cycle_period_us`: the runtime's cycle (0x1006). Throws InputError.
DrivesConfig read_drives_config(const std::string& path, std::uint32_t cycle_period_us);
DrivesConfig parse_drives_config(const std::string& text, std::uint32_t cycle_period_us);

}  // namespace cdcr::cli
