#pragma once
// The simulated board as one object: a virtual CAN bus (node 0 is the
// runtime's) and, for a board with the drives on a bus of their own, a
// second (node 0 the runtime's again), lockstep time, the model region in memory and a silent console,
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
  explicit SimulatedPlatform(std::uint32_t id_offset = 0, bool with_drives_bus = false)
      : runtime_can(bus.node(0), id_offset), runtime_drives_can(drives_bus.node(0), id_offset) {
    if (with_drives_bus) hal.drives_can = &runtime_drives_can;
  }

  VirtualCanBus bus;
  VirtualCanBus drives_bus;  // unused unless with_drives_bus
  LockstepClock clock;
  LockstepTimer timer{clock};
  MemoryModelStorage storage;
  hal::NullConsole console;
  hal::ShiftedCanBus runtime_can;
  hal::ShiftedCanBus runtime_drives_can;
  hal::Hal hal{clock, timer, runtime_can, storage, console};
};

}  // namespace cdcr::sim
