#pragma once
// The CiA 402 backend of hal::Drives: one DriveManager over up to
// kMaxDriveBuses buses, cable i of the model on drive i of the
// configuration.

#include "cdcr/firmware/canopen/drive_manager.hpp"
#include "cdcr/hal/can_bus.hpp"
#include "cdcr/hal/drives.hpp"

namespace cdcr::firmware::canopen {

class Cia402Drives final : public hal::Drives {
 public:
  // buses[b] carries the drives whose DriveChannel::bus is b; the buses
  // beyond config.bus_count may be null. An invalid configuration leaves
  // the drives refused (health()), naming what validate() said.
  Cia402Drives(const DriveManagerConfig& config, hal::CanBus* const (&buses)[kMaxDriveBuses]);

  bool start() override;
  void receive() override;
  bool lengths(double* lengths_mm, int count) override;
  bool command(const double* setpoints_mm, int count) override;
  void transmit() override;
  hal::DrivesHealth health() const override;
  bool recover() override;
  const char* describe(std::uint8_t kind) const override { return to_string(static_cast<DriveFault>(kind)); }
  int drive_count() const override { return manager_.drive_count(); }

  const DriveManager& manager() const { return manager_; }

 private:
  DriveManager manager_;
  hal::CanBus* buses_[kMaxDriveBuses] = {};
  int bus_count_ = 0;
};

// Which condition the runtime reports for a manager's fault.
hal::DrivesCondition condition_of(DriveFault fault);

}  // namespace cdcr::firmware::canopen
