#pragma once
// The CiA 402 drive profile as the manager uses it: the power state machine
// read from the statusword (0x6041) and driven by the controlword (0x6040),
// cyclic synchronous position mode, and the SDO writes that configure a
// drive for it.

#include <cstddef>
#include <cstdint>

#include "cdcr/firmware/canopen/frames.hpp"

namespace cdcr::firmware::canopen::cia402 {

// Objects (CiA 402-2 and CiA 301).
inline constexpr ObjectAddress kControlword{0x6040, 0};
inline constexpr ObjectAddress kStatusword{0x6041, 0};
inline constexpr ObjectAddress kModesOfOperation{0x6060, 0};
inline constexpr ObjectAddress kModesOfOperationDisplay{0x6061, 0};
inline constexpr ObjectAddress kPositionActualValue{0x6064, 0};
inline constexpr ObjectAddress kTargetPosition{0x607A, 0};
inline constexpr ObjectAddress kCommunicationCyclePeriod{0x1006, 0};  // us
inline constexpr ObjectAddress kSynchronousWindowLength{0x1007, 0};   // us
inline constexpr ObjectAddress kProducerHeartbeatTime{0x1017, 0};     // ms
inline constexpr std::int8_t kCyclicSynchronousPosition = 8;

// The power states (CiA 402-2, figure 6), from the statusword's bits 0-3,
// 5 and 6 (table 30).
enum class PowerState : std::uint8_t {
  not_ready_to_switch_on,
  switch_on_disabled,
  ready_to_switch_on,
  switched_on,
  operation_enabled,
  quick_stop_active,
  fault_reaction_active,
  fault,
  unknown,  // a bit pattern the profile does not define
};

inline constexpr PowerState power_state(std::uint16_t statusword) {
  if ((statusword & 0x004F) == 0x0000) return PowerState::not_ready_to_switch_on;
  if ((statusword & 0x004F) == 0x0040) return PowerState::switch_on_disabled;
  if ((statusword & 0x006F) == 0x0021) return PowerState::ready_to_switch_on;
  if ((statusword & 0x006F) == 0x0023) return PowerState::switched_on;
  if ((statusword & 0x006F) == 0x0027) return PowerState::operation_enabled;
  if ((statusword & 0x006F) == 0x0007) return PowerState::quick_stop_active;
  if ((statusword & 0x004F) == 0x000F) return PowerState::fault_reaction_active;
  if ((statusword & 0x004F) == 0x0008) return PowerState::fault;
  return PowerState::unknown;
}

inline constexpr const char* power_state_name(PowerState state) {
  switch (state) {
    case PowerState::not_ready_to_switch_on: return "not ready to switch on";
    case PowerState::switch_on_disabled: return "switch on disabled";
    case PowerState::ready_to_switch_on: return "ready to switch on";
    case PowerState::switched_on: return "switched on";
    case PowerState::operation_enabled: return "operation enabled";
    case PowerState::quick_stop_active: return "quick stop active";
    case PowerState::fault_reaction_active: return "fault reaction active";
    case PowerState::fault: return "fault";
    case PowerState::unknown: break;
  }
  return "undefined statusword";
}

// Controlword commands (CiA 402-2, table 28). Bit 7 (fault reset) acts on
// its rising edge, so a reset is the command, then a controlword without it.
inline constexpr std::uint16_t kDisableVoltage = 0x0000;
inline constexpr std::uint16_t kQuickStop = 0x0002;
inline constexpr std::uint16_t kShutdown = 0x0006;
inline constexpr std::uint16_t kSwitchOn = 0x0007;
inline constexpr std::uint16_t kEnableOperation = 0x000F;
inline constexpr std::uint16_t kFaultReset = 0x0080;

// The command that takes a drive one transition nearer to Operation
// enabled: 2 (shutdown), 3 (switch on), 4 (enable operation); held once
// there. A drive in Fault gets no reset here: that is asked for (see the
// manager), never automatic.
inline constexpr std::uint16_t enabling_controlword(PowerState state) {
  switch (state) {
    case PowerState::switch_on_disabled: return kShutdown;
    case PowerState::ready_to_switch_on: return kSwitchOn;
    case PowerState::switched_on:
    case PowerState::operation_enabled: return kEnableOperation;
    case PowerState::quick_stop_active:  // transition 12 leaves it through switch on disabled
    case PowerState::not_ready_to_switch_on:
    case PowerState::fault_reaction_active:
    case PowerState::fault:
    case PowerState::unknown: break;
  }
  return kDisableVoltage;
}

// PDO parameters (CiA 301, 7.5.2.35-38): the manager maps RPDO1 and TPDO1
// (frames.hpp, DriveCommand / DriveState) and releases both with the SYNC.
inline constexpr std::uint16_t kRpdo1Communication = 0x1400;
inline constexpr std::uint16_t kRpdo1Mapping = 0x1600;
inline constexpr std::uint16_t kTpdo1Communication = 0x1800;
inline constexpr std::uint16_t kTpdo1Mapping = 0x1A00;
inline constexpr std::uint32_t kPdoInvalid = 0x80000000;  // COB-ID bit 31: PDO not valid
inline constexpr std::uint8_t kSynchronousEverySync = 1;  // transmission type 1
inline constexpr std::uint32_t mapping_entry(ObjectAddress object, std::uint8_t bits) {
  return (std::uint32_t(object.index) << 16) | (std::uint32_t(object.subindex) << 8) | bits;
}

// One SDO write of the configuration.
struct ConfigurationWrite {
  ObjectAddress object{};
  std::uint32_t value = 0;
  std::uint8_t size = 0;  // bytes
};

// The writes that configure one drive for the manager, in order: each PDO
// made invalid, mapped and made valid again (CiA 301's procedure for a
// mapping change), CSP mode, the SYNC period and window, the heartbeat.
inline constexpr std::size_t kConfigurationWrites = 18;

struct DriveTiming {
  std::uint32_t cycle_period_us = 1000;
  std::uint32_t sync_window_us = 500;
  std::uint16_t heartbeat_ms = 50;
};

inline void configuration_writes(NodeId node, const DriveTiming& timing,
                                 ConfigurationWrite (&writes)[kConfigurationWrites]) {
  const std::uint32_t rpdo_id = kRpdo1Base + node;
  const std::uint32_t tpdo_id = kTpdo1Base + node;
  const ConfigurationWrite sequence[kConfigurationWrites] = {
      {{kRpdo1Communication, 1}, kPdoInvalid | rpdo_id, 4},
      {{kRpdo1Mapping, 0}, 0, 1},
      {{kRpdo1Mapping, 1}, mapping_entry(kControlword, 16), 4},
      {{kRpdo1Mapping, 2}, mapping_entry(kTargetPosition, 32), 4},
      {{kRpdo1Mapping, 0}, 2, 1},
      {{kRpdo1Communication, 2}, kSynchronousEverySync, 1},
      {{kRpdo1Communication, 1}, rpdo_id, 4},
      {{kTpdo1Communication, 1}, kPdoInvalid | tpdo_id, 4},
      {{kTpdo1Mapping, 0}, 0, 1},
      {{kTpdo1Mapping, 1}, mapping_entry(kStatusword, 16), 4},
      {{kTpdo1Mapping, 2}, mapping_entry(kPositionActualValue, 32), 4},
      {{kTpdo1Mapping, 0}, 2, 1},
      {{kTpdo1Communication, 2}, kSynchronousEverySync, 1},
      {{kTpdo1Communication, 1}, tpdo_id, 4},
      {kModesOfOperation, static_cast<std::uint8_t>(kCyclicSynchronousPosition), 1},
      {kCommunicationCyclePeriod, timing.cycle_period_us, 4},
      {kSynchronousWindowLength, timing.sync_window_us, 4},
      {kProducerHeartbeatTime, timing.heartbeat_ms, 2},
  };
  for (std::size_t i = 0; i < kConfigurationWrites; ++i) writes[i] = sequence[i];
}

}  // namespace cdcr::firmware::canopen::cia402
