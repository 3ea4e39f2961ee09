#pragma once
// CAN with 11-bit identifiers, classical (up to 8 data bytes) and CAN FD
// (up to 64), non-blocking. A controller that cannot send FD frames refuses
// them (fd_capable() false); the runtime sends FD frames only on a bus
// configured for them.

#include <cstddef>
#include <cstdint>

#include "cdcr/hal/interface.hpp"

namespace cdcr::hal {

inline constexpr std::uint32_t kMaxStandardId = 0x7FF;
inline constexpr std::uint8_t kMaxDataBytes = 8;     // a classical frame
inline constexpr std::uint8_t kMaxFdDataBytes = 64;  // a CAN FD frame

// The lengths a CAN FD frame can carry (0 to 8, 12, 16, 20, 24, 32, 48, 64);
// a classical frame carries 0 to 8.
inline constexpr bool is_fd_length(std::size_t length) {
  return length <= 8 || length == 12 || length == 16 || length == 20 || length == 24 || length == 32 ||
         length == 48 || length == 64;
}

// CanFrame::flags.
inline constexpr std::uint8_t kCanFdFrame = 0x01;        // FDF: a CAN FD frame
inline constexpr std::uint8_t kCanBitRateSwitch = 0x02;  // BRS: its data phase at the data bit rate (FD only)

struct CanFrame {
  std::uint32_t id = 0;   // 11-bit standard identifier
  std::uint8_t dlc = 0;   // data length in bytes: 0..8, or an FD length (is_fd_length) with kCanFdFrame
  std::uint8_t flags = 0; // kCanFdFrame, kCanBitRateSwitch
  std::uint8_t data[kMaxFdDataBytes] = {};

  constexpr bool fd() const { return (flags & kCanFdFrame) != 0; }
  constexpr bool bit_rate_switch() const { return (flags & kCanBitRateSwitch) != 0; }
};

// What send() accepts; anything else is refused as invalid_frame: an FD
// frame only where the controller sends FD frames.
inline constexpr bool is_valid(const CanFrame& frame, bool fd_capable = false) {
  if (frame.id > kMaxStandardId || (frame.flags & ~(kCanFdFrame | kCanBitRateSwitch)) != 0) return false;
  if (!frame.fd()) return frame.dlc <= kMaxDataBytes && frame.flags == 0;
  return fd_capable && is_fd_length(frame.dlc);
}

enum class CanStatus : std::uint8_t {
  ok = 0,
  empty,          // receive: nothing pending
  queue_full,     // send: no room in the transmit queue, frame dropped
  invalid_frame,  // send: id beyond 11 bits, a length the format cannot carry, or FD on a classical controller
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
  // Whether send() takes CAN FD frames (and receive() may return them).
  virtual bool fd_capable() const { return false; }

 protected:
  ~CanBus() = default;
};

}  // namespace cdcr::hal
