#pragma once
// Classic CAN (11-bit identifiers, up to 8 data bytes), non-blocking.

#include <cstddef>
#include <cstdint>

#include "cdcr/hal/interface.hpp"

namespace cdcr::hal {

struct CanFrame {
  std::uint32_t id = 0;  // 11-bit standard identifier
  std::uint8_t dlc = 0;  // 0..8
  std::uint8_t data[8] = {};
};

inline constexpr std::uint32_t kMaxStandardId = 0x7FF;
inline constexpr std::uint8_t kMaxDataBytes = 8;

// What send() accepts; anything else is refused as invalid_frame.
inline constexpr bool is_valid(const CanFrame& frame) {
  return frame.id <= kMaxStandardId && frame.dlc <= kMaxDataBytes;
}

enum class CanStatus : std::uint8_t {
  ok = 0,
  empty,          // receive: nothing pending
  queue_full,     // send: no room in the transmit queue, frame dropped
  invalid_frame,  // send: id beyond 11 bits or dlc beyond 8
  bus_off,        // controller off the bus after too many errors
};

// A frame is accepted when (frame.id & mask) == (id & mask). With no filter
// set, every frame is accepted.
struct CanFilter {
  std::uint32_t id = 0;
  std::uint32_t mask = 0;
};

// Acceptance filters every CanBus must take in one set_filters() call: the
// runtime sets no more than these.
inline constexpr std::size_t kMaxCanFilters = 4;

struct CanErrorCounters {
  std::uint32_t tx_dropped = 0;   // frames refused by send()
  std::uint32_t rx_overruns = 0;  // frames lost because the receive queue was full
  std::uint32_t bus_errors = 0;   // error frames seen by the controller
};

class CanBus : public Interface {
 public:
  virtual CanStatus send(const CanFrame& frame) = 0;
  virtual CanStatus receive(CanFrame& frame) = 0;
  // Replaces the acceptance filters; false if more than the controller holds.
  virtual bool set_filters(const CanFilter* filters, std::size_t count) = 0;
  virtual CanErrorCounters error_counters() const = 0;

 protected:
  ~CanBus() = default;
};

}  // namespace cdcr::hal
