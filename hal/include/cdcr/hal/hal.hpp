#pragma once
// The one object a platform hands the runtime: every peripheral it may use,
// each behind a narrow interface. Runtime code includes only this directory,
// never a backend's headers; a backend builds a Hal from its own objects.

#include "cdcr/hal/can_bus.hpp"
#include "cdcr/hal/clock.hpp"
#include "cdcr/hal/console.hpp"
#include "cdcr/hal/drives.hpp"
#include "cdcr/hal/flash.hpp"
#include "cdcr/hal/model_storage.hpp"

namespace cdcr::hal {

struct Hal {
  MonotonicClock& clock;
  PeriodicTimer& timer;
  CanBus& can;
  ModelStorage& model_storage;
  Console& console;
  // Where model updates are written (A/B slots); none: the model is
  // model_storage's and cannot be updated over the bus.
  Flash* flash = nullptr;
  // A second bus for the drives (their CABLE_FEEDBACK in, the setpoints
  // out); none: the drives share `can` with the host.
  CanBus* drives_can = nullptr;
  // Drives of another kind than the protocol's (drives.hpp), on buses of
  // their own: CABLE_FEEDBACK is then ignored and drives_can unused.
  Drives* drives = nullptr;
};

}  // namespace cdcr::hal
