#include "cdcr/firmware/canopen/cia402_drives.hpp"

#include "cdcr/firmware/capacity.hpp"

namespace cdcr::firmware::canopen {

hal::DrivesCondition condition_of(DriveFault fault) {
  switch (fault) {
    case DriveFault::none: return hal::DrivesCondition::ready;
    case DriveFault::boot_silent:
    case DriveFault::sdo_timeout:
    case DriveFault::heartbeat_lost:
    case DriveFault::nmt_left:
    case DriveFault::input_stale: return hal::DrivesCondition::silent;
    case DriveFault::emergency:
    case DriveFault::drive_fault:
    case DriveFault::left_operation:
    case DriveFault::enable_timeout: return hal::DrivesCondition::faulted;
    case DriveFault::config_invalid:
    case DriveFault::sdo_aborted:
    case DriveFault::sdo_unexpected:
    case DriveFault::setpoint_range: return hal::DrivesCondition::refused;
  }
  return hal::DrivesCondition::faulted;
}

Cia402Drives::Cia402Drives(const DriveManagerConfig& config, hal::CanBus* const (&buses)[kMaxDriveBuses])
    : manager_(config) {
  bus_count_ = config.bus_count >= 1 && config.bus_count <= kMaxDriveBuses ? config.bus_count : 0;
  for (int b = 0; b < bus_count_; ++b) {
    buses_[b] = buses[b];
    // A bus the configuration names but nobody gave: nothing can run.
    if (buses_[b] == nullptr) {
      DriveManagerConfig none;
      manager_.configure(none);
      bus_count_ = 0;
      return;
    }
  }
}

bool Cia402Drives::start() {
  // What the drives send: EMCY, TPDO1, the SDO server's replies, heartbeats.
  static constexpr hal::CanFilter kFilters[] = {
      {kEmcyBase, kFunctionMask}, {kTpdo1Base, kFunctionMask}, {kSdoServerBase, kFunctionMask},
      {kHeartbeatBase, kFunctionMask}};
  static_assert(sizeof(kFilters) / sizeof(kFilters[0]) <= kMaxCanFilters, "more filters than a controller must offer");
  bool accepted = true;
  for (int b = 0; b < bus_count_; ++b)
    accepted = buses_[b]->set_filters(kFilters, sizeof(kFilters) / sizeof(kFilters[0])) && accepted;
  return accepted;
}

void Cia402Drives::receive() {
  hal::CanFrame frame;
  for (int b = 0; b < bus_count_; ++b) {
    // As the runtime's own buses: a flood waits for the next cycle.
    for (int n = 0; n < kMaxRxFramesPerCycle && buses_[b]->receive(frame) == hal::CanStatus::ok; ++n)
      manager_.take(frame, b);
  }
}

bool Cia402Drives::lengths(double* lengths_mm, int count) {
  if (count != manager_.drive_count() || !manager_.positions_fresh()) return false;
  if (manager_.phase() != DrivePhase::operational) return false;
  for (int i = 0; i < count; ++i) lengths_mm[i] = manager_.length_mm(i);
  return true;
}

bool Cia402Drives::command(const double* setpoints_mm, int count) {
  if (manager_.phase() != DrivePhase::operational) return false;
  return manager_.set_setpoints(setpoints_mm, count);
}

void Cia402Drives::transmit() {
  if (bus_count_ > 0) manager_.run_cycle(buses_);
}

hal::DrivesHealth Cia402Drives::health() const {
  hal::DrivesHealth health;
  const DriveFaultReport& fault = manager_.fault();
  if (manager_.phase() == DrivePhase::fault) {
    health.condition = condition_of(fault.fault);
    health.drive = fault.node;
    health.cable = static_cast<std::int16_t>(fault.cable);
    health.kind = static_cast<std::uint8_t>(fault.fault);
    health.detail = fault.detail;
  } else {
    health.condition =
        manager_.phase() == DrivePhase::operational ? hal::DrivesCondition::ready : hal::DrivesCondition::starting;
  }
  return health;
}

bool Cia402Drives::recover() {
  if (manager_.phase() != DrivePhase::fault || manager_.fault().fault == DriveFault::config_invalid) return false;
  manager_.recover();
  return true;
}

}  // namespace cdcr::firmware::canopen
