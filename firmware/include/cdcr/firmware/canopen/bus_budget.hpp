#pragma once
// The bus budget of CiA 402 drives on a bus (protocol/bus_budget.hpp's
// worst-case frame times and limit): in every cycle the manager's SYNC and
// one RPDO1 per drive, each drive's TPDO1 answer, and each drive's heartbeat
// every heartbeat period. NMT and the SDO configuration run before the
// drives are enabled, EMCY only on a fault: they use the room between the
// load and the limit.

#include <cstdint>

#include "cdcr/firmware/canopen/frames.hpp"
#include "cdcr/firmware/protocol/bus_budget.hpp"

namespace cdcr::firmware::canopen {

inline protocol::BusBudget cia402_bus_budget(int drives, std::uint32_t cycle_hz, std::uint16_t heartbeat_ms,
                                             const protocol::BusSetup& bus) {
  protocol::BusBudget budget;
  const double cycles = double(cycle_hz);
  protocol::detail::add_message(budget, bus, "SYNC", 0, cycles);
  protocol::detail::add_message(budget, bus, "RPDO1", kProcessDataBytes, double(drives) * cycles);
  protocol::detail::add_message(budget, bus, "TPDO1", kProcessDataBytes, double(drives) * cycles);
  if (heartbeat_ms > 0) protocol::detail::add_message(budget, bus, "HEARTBEAT", 1, double(drives) * 1000.0 / heartbeat_ms);
  return budget;
}

}  // namespace cdcr::firmware::canopen
