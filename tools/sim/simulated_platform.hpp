#pragma once
// The simulated board as one object: a virtual CAN bus (node 0 is the
// runtime's), lockstep time, the model region in memory and a silent console,
// wired into the Hal the firmware takes. Host programs that run the firmware
// on the simulated robot start from this.

#include <cdcr/hal/console.hpp>
#include <cstdint>

#include <cdcr/hal/hal.hpp>
#include <cdcr/hal/shifted_can_bus.hpp>
#include <cdcr/sim/lockstep_timer.hpp>
#include <cdcr/sim/memory_model_storage.hpp>
#include <cdcr/sim/virtual_can.hpp>

namespace cdcr::sim {

struct SimulatedPlatform {
  // `id_offset`: the runtime's identifiers moved on the bus
  // (protocol::id_offset of an identifier base); 0 leaves them.
  explicit SimulatedPlatform(std::uint32_t id_offset = 0) : runtime_can(bus.node(0), id_offset) {}

  VirtualCanBus bus;
  LockstepClock clock;
  LockstepTimer timer{clock};
  MemoryModelStorage storage;
  hal::NullConsole console;
  hal::ShiftedCanBus runtime_can;
  hal::Hal hal{clock, timer, runtime_can, storage, console};
};

}  // namespace cdcr::sim
