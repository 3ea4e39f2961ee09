#include "cdcr/firmware/canopen/drive_manager.hpp"

#include <cmath>

namespace cdcr::firmware::canopen {

namespace {
constexpr double kMaxCountsPerMm = 1e6;
constexpr double kMaxOffsetMm = 1e4;
constexpr double kMaxSpeedMmPerS = 1e4;
constexpr std::uint16_t kStatuswordFault = 0x0008;  // bit 3
}  // namespace

DriveConfigStatus validate(const DriveManagerConfig& config) {
  if (config.drive_count < 1 || config.drive_count > kMaxDrives) return DriveConfigStatus::no_drives;
  if (config.bus_count < 1 || config.bus_count > kMaxDriveBuses) return DriveConfigStatus::bus_invalid;
  for (int i = 0; i < config.drive_count; ++i) {
    const DriveChannel& drive = config.drives[i];
    if (drive.bus >= config.bus_count) return DriveConfigStatus::bus_invalid;
    if (!is_valid_node(drive.node)) return DriveConfigStatus::node_invalid;
    for (int j = 0; j < i; ++j)
      if (config.drives[j].bus == drive.bus && config.drives[j].node == drive.node)
        return DriveConfigStatus::node_repeated;
    if (!(std::fabs(drive.counts_per_mm) > 0.0) || !(std::fabs(drive.counts_per_mm) <= kMaxCountsPerMm))
      return DriveConfigStatus::scale_invalid;
    if (!(std::fabs(drive.offset_mm) <= kMaxOffsetMm)) return DriveConfigStatus::offset_invalid;
  }
  const cia402::DriveTiming& timing = config.timing;
  if (timing.cycle_period_us == 0 || timing.sync_window_us > timing.cycle_period_us || timing.heartbeat_ms == 0 ||
      config.heartbeat_periods_lost == 0 || config.stale_cycles == 0 ||
      !(config.max_speed_mm_per_s > 0.0 && config.max_speed_mm_per_s <= kMaxSpeedMmPerS))
    return DriveConfigStatus::timing_invalid;
  return DriveConfigStatus::ok;
}

const char* to_string(DriveConfigStatus status) {
  switch (status) {
    case DriveConfigStatus::ok: return "ok";
    case DriveConfigStatus::no_drives: return "no drives, or more than one per cable";
    case DriveConfigStatus::bus_invalid: return "no bus, more than 4, or a drive on a bus not configured";
    case DriveConfigStatus::node_invalid: return "a node id outside 1..127";
    case DriveConfigStatus::node_repeated: return "two cables on one node id of a bus";
    case DriveConfigStatus::scale_invalid: return "counts per mm zero, not a number or beyond 1e6";
    case DriveConfigStatus::offset_invalid: return "offset not a number or beyond 1e4 mm";
    case DriveConfigStatus::timing_invalid:
      return "cycle period 0, SYNC window beyond it, heartbeat or staleness 0, or speed limit not in (0, 1e4] mm/s";
  }
  return "unknown";
}

const char* to_string(DrivePhase phase) {
  switch (phase) {
    case DrivePhase::reset: return "reset";
    case DrivePhase::boot: return "boot";
    case DrivePhase::configure: return "configure";
    case DrivePhase::start: return "start";
    case DrivePhase::enable: return "enable";
    case DrivePhase::operational: return "operational";
    case DrivePhase::fault: return "fault";
  }
  return "unknown";
}

const char* to_string(DriveFault fault) {
  switch (fault) {
    case DriveFault::none: return "none";
    case DriveFault::config_invalid: return "drive configuration invalid";
    case DriveFault::boot_silent: return "no boot-up message";
    case DriveFault::sdo_aborted: return "configuration write refused";
    case DriveFault::sdo_timeout: return "no SDO answer";
    case DriveFault::sdo_unexpected: return "unexpected SDO answer";
    case DriveFault::enable_timeout: return "not enabled in time";
    case DriveFault::heartbeat_lost: return "heartbeat lost";
    case DriveFault::nmt_left: return "left NMT operational";
    case DriveFault::emergency: return "emergency";
    case DriveFault::drive_fault: return "drive fault";
    case DriveFault::left_operation: return "left operation enabled";
    case DriveFault::input_stale: return "position stale";
    case DriveFault::setpoint_range: return "setpoint beyond the position range";
  }
  return "unknown";
}

void DriveManager::configure(const DriveManagerConfig& config) {
  config_ = config;
  for (Drive& drive : drives_) drive = Drive{};
  fault_ = DriveFaultReport{};
  phase_ = DrivePhase::reset;
  phase_start_ = cycle_;
  cycles_in_phase_ = 0;
  has_setpoints_ = false;
  resetting_faults_ = false;
  const DriveConfigStatus status = validate(config);
  if (status != DriveConfigStatus::ok) {
    config_.drive_count = 0;
    phase_ = DrivePhase::fault;
    fault_.fault = DriveFault::config_invalid;
    fault_.detail = static_cast<std::uint32_t>(status);
    return;
  }
  const double step_mm = config_.max_speed_mm_per_s * double(config_.timing.cycle_period_us) * 1e-6;
  for (int i = 0; i < config_.drive_count; ++i) {
    mm_per_count_[i] = 1.0 / config_.drives[i].counts_per_mm;
    const double step = std::round(step_mm * std::fabs(config_.drives[i].counts_per_mm));
    ramp_counts_[i] = step < 1.0 ? 1 : step > 2147483647.0 ? 2147483647 : std::int32_t(step);
  }
}

int DriveManager::find(int bus, NodeId node) const {
  for (int i = 0; i < config_.drive_count; ++i)
    if (config_.drives[i].bus == bus && config_.drives[i].node == node) return i;
  return -1;
}

void DriveManager::broadcast(Buses buses, const hal::CanFrame& frame) {
  for (int b = 0; b < config_.bus_count; ++b) buses[b]->send(frame);
}

std::uint32_t DriveManager::cycles_of_ms(std::uint32_t ms) const {
  const std::uint64_t us = std::uint64_t(ms) * 1000;
  return static_cast<std::uint32_t>((us + config_.timing.cycle_period_us - 1) / config_.timing.cycle_period_us);
}

void DriveManager::enter(DrivePhase phase) {
  phase_ = phase;
  phase_start_ = cycle_;
  cycles_in_phase_ = 0;
}

void DriveManager::fail(DriveFault fault, int cable, std::uint32_t detail, ObjectAddress object) {
  if (phase_ == DrivePhase::fault) return;  // the first fault is the one reported
  fault_.fault = fault;
  fault_.cable = cable;
  fault_.node = cable >= 0 ? config_.drives[cable].node : 0;
  fault_.detail = detail;
  fault_.object = object;
  enter(DrivePhase::fault);
}

void DriveManager::recover() {
  if (phase_ != DrivePhase::fault || config_.drive_count == 0) return;
  fault_ = DriveFaultReport{};
  resetting_faults_ = true;
  enter(DrivePhase::reset);
}

bool DriveManager::take(const hal::CanFrame& frame, int bus) {
  if (frame.fd()) return false;
  const std::uint32_t function = frame.id & kFunctionMask;
  const int cable = find(bus, static_cast<NodeId>(frame.id & kNodeMask));
  if (cable < 0) return false;
  Drive& drive = drives_[cable];
  switch (function) {
    case kHeartbeatBase: {
      Heartbeat heartbeat;
      if (!decode_heartbeat(frame, heartbeat)) return false;
      drive.heartbeat_seen = true;
      drive.heartbeat_cycle = cycle_;
      drive.nmt = heartbeat.state;
      if (heartbeat.state == NmtState::boot_up) {
        drive.booted = true;
        // A drive that boots again has lost its configuration.
        if (phase_ == DrivePhase::start || phase_ == DrivePhase::enable || phase_ == DrivePhase::operational)
          fail(DriveFault::nmt_left, cable, static_cast<std::uint32_t>(heartbeat.state));
      } else if (heartbeat.state == NmtState::operational) {
        drive.seen_operational = true;
      } else if (phase_ == DrivePhase::operational ||
                 (phase_ == DrivePhase::enable && drive.seen_operational)) {
        // In enable, a heartbeat the drive sent before the NMT start reached
        // it may still arrive: only one after an operational one counts.
        fail(DriveFault::nmt_left, cable, static_cast<std::uint32_t>(heartbeat.state));
      }
      return true;
    }
    case kEmcyBase: {
      Emergency emergency;
      if (!decode_emergency(frame, emergency)) return false;
      if (!emergency.clears() && phase_ != DrivePhase::reset && phase_ != DrivePhase::boot)
        fail(DriveFault::emergency, cable, emergency.error_code);
      return true;
    }
    case kSdoServerBase: {
      SdoReply reply;
      if (!decode_sdo_reply(frame, reply)) return false;
      take_sdo(cable, reply);
      return true;
    }
    case kTpdo1Base: {
      DriveState state;
      if (!decode_tpdo(frame, state)) return false;
      take_tpdo(cable, state);
      return true;
    }
    default: return false;
  }
}

void DriveManager::take_sdo(int cable, const SdoReply& reply) {
  Drive& drive = drives_[cable];
  // An answer nobody waits for (a repeat, or one after its timeout) changes nothing.
  if (phase_ != DrivePhase::configure || !drive.sdo_pending) return;
  cia402::ConfigurationWrite writes[cia402::kConfigurationWrites];
  cia402::configuration_writes(config_.drives[cable].node, config_.timing, writes);
  const cia402::ConfigurationWrite& write = writes[drive.next_write];
  if (!(reply.object == write.object)) {
    fail(DriveFault::sdo_unexpected, cable, 0, reply.object);
    return;
  }
  if (reply.kind == SdoReply::Kind::abort) {
    fail(DriveFault::sdo_aborted, cable, reply.abort_code, write.object);
    return;
  }
  if (reply.kind != SdoReply::Kind::download_done) {
    fail(DriveFault::sdo_unexpected, cable, 0, write.object);
    return;
  }
  drive.sdo_pending = false;
  ++drive.next_write;
}

void DriveManager::take_tpdo(int cable, const DriveState& state) {
  Drive& drive = drives_[cable];
  // Twice after one SYNC (a repeat, or a late one and its successor): the
  // latest counts.
  if (drive.tpdo_seen) ++repeated_pdos_;
  drive.tpdo_seen = true;
  drive.has_position = true;
  drive.tpdo_cycle = cycle_;
  drive.statusword = state.statusword;
  drive.actual = state.actual_position;
  if (phase_ != DrivePhase::operational) return;
  if ((state.statusword & kStatuswordFault) != 0) {
    fail(DriveFault::drive_fault, cable, state.statusword);
  } else if (cia402::power_state(state.statusword) != cia402::PowerState::operation_enabled) {
    fail(DriveFault::left_operation, cable, state.statusword);
  }
}

bool DriveManager::positions_fresh() const {
  if (config_.drive_count == 0) return false;
  for (int i = 0; i < config_.drive_count; ++i)
    if (!drives_[i].tpdo_seen) return false;
  return true;
}

double DriveManager::length_mm(int cable) const {
  const DriveChannel& channel = config_.drives[cable];
  return double(drives_[cable].actual) * mm_per_count_[cable] + channel.offset_mm;
}

bool DriveManager::set_setpoints(const double* lengths_mm, int count) {
  if (count != config_.drive_count || count == 0) return false;
  std::int32_t counts[kMaxDrives];
  for (int i = 0; i < count; ++i) {
    const DriveChannel& channel = config_.drives[i];
    const double raw = std::round((lengths_mm[i] - channel.offset_mm) * channel.counts_per_mm);
    if (!(raw >= -2147483648.0 && raw <= 2147483647.0)) {
      fail(DriveFault::setpoint_range, i);
      return false;
    }
    counts[i] = static_cast<std::int32_t>(raw);
  }
  for (int i = 0; i < count; ++i) setpoint_[i] = counts[i];
  has_setpoints_ = true;
  return true;
}

void DriveManager::check_heartbeats() {
  const std::uint32_t lost = cycles_of_ms(config_.timing.heartbeat_ms * config_.heartbeat_periods_lost);
  for (int i = 0; i < config_.drive_count; ++i) {
    if (cycle_ - drives_[i].heartbeat_cycle > lost) {
      fail(DriveFault::heartbeat_lost, i, drives_[i].heartbeat_seen ? 1u : 0u);
      return;
    }
  }
}

void DriveManager::run_configure(Buses buses) {
  const std::uint32_t timeout = cycles_of_ms(config_.sdo_timeout_ms);
  bool done = true;
  int sent = 0;
  for (int k = 0; k < config_.drive_count; ++k) {
    const int cable = (sdo_cursor_ + k) % config_.drive_count;
    Drive& drive = drives_[cable];
    if (drive.next_write >= int(cia402::kConfigurationWrites)) continue;
    done = false;
    cia402::ConfigurationWrite writes[cia402::kConfigurationWrites];
    cia402::configuration_writes(config_.drives[cable].node, config_.timing, writes);
    const cia402::ConfigurationWrite& write = writes[drive.next_write];
    if (drive.sdo_pending) {
      if (cycle_ - drive.sdo_sent_cycle > timeout) {
        fail(DriveFault::sdo_timeout, cable, sdo::kAbortTimeout, write.object);
        return;
      }
      continue;
    }
    if (sent == kMaxSdoRequestsPerCycle) continue;
    hal::CanFrame frame;
    sdo_download_frame(config_.drives[cable].node, write.object, write.value, write.size, frame);
    // A request the controller did not queue goes again next cycle.
    if (buses[config_.drives[cable].bus]->send(frame) != hal::CanStatus::ok) continue;
    drive.sdo_pending = true;
    drive.sdo_sent_cycle = cycle_;
    ++sent;
  }
  if (config_.drive_count > 0) sdo_cursor_ = (sdo_cursor_ + 1) % config_.drive_count;
  if (done) enter(DrivePhase::start);
}

// The RPDOs, then the SYNC that releases them and asks for the TPDOs.
void DriveManager::send_process_data(Buses buses, bool operating) {
  for (int i = 0; i < config_.drive_count; ++i) {
    Drive& drive = drives_[i];
    DriveCommand command;
    command.node = config_.drives[i].node;
    const cia402::PowerState state = cia402::power_state(drive.statusword);
    if (phase_ == DrivePhase::fault) {
      command.controlword = cia402::kQuickStop;
      drive.target = drive.actual;
    } else if (operating) {
      command.controlword = cia402::kEnableOperation;
      if (has_setpoints_) {
        // CSP takes a new position every SYNC: the manager ramps to the
        // setpoint within the speed limit, so no step trips the drive's
        // following-error check.
        const std::int64_t step = ramp_counts_[i];
        const std::int64_t delta = std::int64_t(setpoint_[i]) - drive.target;
        drive.target = delta <= step && delta >= -step ? setpoint_[i]
                                                       : std::int32_t(drive.target + (delta > 0 ? step : -step));
      }
    } else if (!drive.has_position) {
      command.controlword = cia402::kDisableVoltage;
    } else if (state == cia402::PowerState::fault || state == cia402::PowerState::fault_reaction_active) {
      // Fault reset acts on bit 7's rising edge: alternate it with 0.
      command.controlword = resetting_faults_ && (cycles_in_phase_ % 2 == 0) ? cia402::kFaultReset
                                                                             : cia402::kDisableVoltage;
      drive.target = drive.actual;
    } else {
      command.controlword = cia402::enabling_controlword(state);
      drive.target = drive.actual;  // enabled where it stands
    }
    command.target_position = drive.target;
    buses[config_.drives[i].bus]->send(rpdo_frame(command));
  }
  broadcast(buses, sync_frame());
  for (int i = 0; i < config_.drive_count; ++i) drives_[i].tpdo_seen = false;
}

void DriveManager::run_cycle(Buses buses) {
  ++cycle_;
  cycles_in_phase_ = cycle_ - phase_start_;
  switch (phase_) {
    case DrivePhase::reset:
      for (int i = 0; i < config_.drive_count; ++i) {
        const bool had_position = drives_[i].has_position;
        const std::uint16_t statusword = drives_[i].statusword;
        drives_[i] = Drive{};
        // A drive's CiA 402 state outlives its communication reset.
        drives_[i].has_position = had_position;
        drives_[i].statusword = statusword;
      }
      has_setpoints_ = false;
      broadcast(buses, nmt_frame(NmtCommand::reset_communication, 0));
      enter(DrivePhase::boot);
      return;
    case DrivePhase::boot: {
      int silent = -1;
      for (int i = 0; i < config_.drive_count && silent < 0; ++i)
        if (!drives_[i].booted) silent = i;
      if (silent < 0) {
        enter(DrivePhase::configure);
      } else if (cycles_in_phase_ > cycles_of_ms(config_.boot_timeout_ms)) {
        fail(DriveFault::boot_silent, silent);
      }
      return;
    }
    case DrivePhase::configure: run_configure(buses); return;
    case DrivePhase::start:
      broadcast(buses, nmt_frame(NmtCommand::start, 0));
      // Heartbeats count from here: the producer time was just written.
      for (int i = 0; i < config_.drive_count; ++i) drives_[i].heartbeat_cycle = cycle_;
      enter(DrivePhase::enable);
      return;
    case DrivePhase::enable: {
      check_heartbeats();
      if (phase_ == DrivePhase::fault) break;
      int waiting = -1;
      for (int i = 0; i < config_.drive_count && waiting < 0; ++i)
        if (!drives_[i].has_position ||
            cia402::power_state(drives_[i].statusword) != cia402::PowerState::operation_enabled)
          waiting = i;
      if (waiting < 0) {
        resetting_faults_ = false;
        enter(DrivePhase::operational);
        send_process_data(buses, true);
        return;
      }
      if (cycles_in_phase_ > cycles_of_ms(config_.enable_timeout_ms)) {
        fail(DriveFault::enable_timeout, waiting, drives_[waiting].statusword);
        break;
      }
      send_process_data(buses, false);
      return;
    }
    case DrivePhase::operational:
      check_heartbeats();
      for (int i = 0; i < config_.drive_count && phase_ == DrivePhase::operational; ++i)
        if (cycle_ - drives_[i].tpdo_cycle > config_.stale_cycles) fail(DriveFault::input_stale, i);
      if (phase_ != DrivePhase::operational) break;
      send_process_data(buses, true);
      return;
    case DrivePhase::fault: break;
  }
  // In fault: quick stop where the drives stand, and the SYNC goes on so
  // their positions keep coming.
  if (config_.drive_count > 0) send_process_data(buses, false);
}

}  // namespace cdcr::firmware::canopen
