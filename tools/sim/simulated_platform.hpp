#pragma once
// The simulated board as one object: a virtual CAN bus (node 0 is the
// runtime's), lockstep time, the model region in memory and a silent console,
// wired into the Hal the firmware takes. Host programs that run the firmware
// on the simulated robot start from this.

#include <cdcr/hal/console.hpp>
#include <cdcr/hal/hal.hpp>
#include <cdcr/sim/lockstep_timer.hpp>
#include <cdcr/sim/memory_model_storage.hpp>
#include <cdcr/sim/virtual_can.hpp>

namespace cdcr::sim {

struct SimulatedPlatform {
  VirtualCanBus bus;
  LockstepClock clock;
  LockstepTimer timer{clock};
  MemoryModelStorage storage;
  hal::NullConsole console;
  hal::Hal hal{clock, timer, bus.node(0), storage, console};
};

}  // namespace cdcr::sim
