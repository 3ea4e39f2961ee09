#pragma once
// The cable drives: where the cable lengths come from and where the
// setpoints go. Without a Drives object the runtime's drives speak its own
// protocol (CABLE_FEEDBACK in, CABLE_SETPOINT out, on Hal::drives_can or
// Hal::can); a Drives backend replaces that with drives of another kind
// (CiA 402 over CANopen: firmware/canopen; the simulated robot's), on buses
// of its own.
//
// The runtime calls, in every cycle: receive() first, then lengths(); after
// its work, command() when it has new setpoints, then transmit() last. No
// call blocks.

#include <cstdint>

#include "cdcr/hal/interface.hpp"

namespace cdcr::hal {

// The drives' state as the runtime reports it.
enum class DrivesCondition : std::uint8_t {
  starting,           // configuring or enabling; no lengths yet
  ready,              // lengths arrive every cycle, setpoints are taken
  silent,             // a drive stopped answering (boot, configuration, heartbeat, its position)
  faulted,            // a drive reported a fault, or left the state it must be in
  refused,            // the drives' configuration was refused (by a drive or as given)
};

struct DrivesHealth {
  DrivesCondition condition = DrivesCondition::starting;
  std::uint8_t drive = 0;    // the drive it is about (its bus address), 0: none
  std::int16_t cable = -1;   // its cable
  std::uint8_t kind = 0;     // the backend's own reason (for the console and logs)
  std::uint32_t detail = 0;  // the backend's detail (an abort code, an error code, a statusword)
  bool failed() const {
    return condition == DrivesCondition::silent || condition == DrivesCondition::faulted ||
           condition == DrivesCondition::refused;
  }
};

class Drives : public Interface {
 public:
  // Once, at the runtime's init: sets the buses' filters and starts the
  // drives; false if a bus refused its filters (the drives still start).
  virtual bool start() = 0;
  // Start of a cycle: what the drives sent since the last.
  virtual void receive() = 0;
  // Every cable's length in mm, cable i of the model in lengths_mm[i], when
  // a complete new set arrived this cycle; false otherwise (nothing
  // written). count is the model's cable count.
  virtual bool lengths(double* lengths_mm, int count) = 0;
  // The setpoints of every cable in mm; false if the drives do not take
  // them (not ready, or a length beyond a drive's range).
  virtual bool command(const double* setpoints_mm, int count) = 0;
  // End of a cycle: what the drives are owed this cycle.
  virtual void transmit() = 0;
  virtual DrivesHealth health() const = 0;
  // After a failure: start the drives again; false if there is none.
  virtual bool recover() = 0;
  // A short name of health().kind, for the console.
  virtual const char* describe(std::uint8_t kind) const = 0;
  // How many drives it runs: the runtime charges each a share of the cycle.
  virtual int drive_count() const = 0;

 protected:
  ~Drives() = default;
};

}  // namespace cdcr::hal
