#pragma once
// Register-level driver of the Xilinx CAN controller (the CANPS IP of the
// Zynq-7000 and Zynq UltraScale+, UG1085 "CAN Controller"), polled. Classic
// CAN with 11-bit identifiers: extended and remote frames are neither sent
// nor accepted. Everything here is one register access or a short bounded
// poll; nothing blocks on the bus.
//
// The controller's parts as this driver uses them:
//   TX FIFO (64 frames)     transmit(): the runtime's frames, in order
//   TX high-priority buffer transmit_high_priority(): one frame that goes
//                           ahead of the FIFO
//   RX FIFO (64 frames)     receive(): one frame at a time; XilinxCan drains
//                           it into a ring, which is where an interrupt
//                           handler would put them
//   acceptance filters (4)  set_filters(): identifier/mask pairs
//   ECR, ESR, SR.ESTAT      error counters, error kinds, error-active /
//                           passive / bus-off state

#include <cstddef>
#include <cstdint>

#include <cdcr/baremetal/mmio.hpp>
#include <cdcr/hal/can_bus.hpp>

#include "cdcr/zynqmp/can_bit_timing.hpp"

namespace cdcr::zynqmp {

enum class CanMode : std::uint8_t {
  normal,
  loopback,  // the controller receives what it sends and drives nothing onto the bus
};

// SR.ESTAT.
enum class CanErrorState : std::uint8_t {
  configuration = 0,
  error_active = 1,
  bus_off = 2,
  error_passive = 3,
};

// What the controller's error registers say.
struct CanControllerErrors {
  std::uint8_t transmit_error_count = 0;  // ECR.TEC
  std::uint8_t receive_error_count = 0;   // ECR.REC
  CanErrorState state = CanErrorState::configuration;
};

// The acceptance filters the controller holds.
inline constexpr std::size_t kXilinxCanFilters = 4;
// Frames each of its FIFOs holds.
inline constexpr std::size_t kXilinxCanFifoFrames = 64;

class XilinxCanController {
 public:
  explicit constexpr XilinxCanController(std::uintptr_t base) : base_(base) {}

  // Resets the controller, programs the bit timing and the mode, and leaves
  // configuration mode. False, with the controller left in configuration
  // mode, for a timing the controller cannot take or when it does not reach
  // the mode.
  bool start(const CanBitTiming& timing, CanMode mode = CanMode::normal);
  // The bit timing the controller holds (BRPR, BTR).
  CanBitTiming bit_timing() const;

  // Into the TX FIFO: ok, queue_full (FIFO full), invalid_frame, or bus_off.
  hal::CanStatus transmit(const hal::CanFrame& frame);
  // Into the high-priority buffer, sent before anything in the FIFO:
  // queue_full while the buffer still holds a frame.
  hal::CanStatus transmit_high_priority(const hal::CanFrame& frame);

  // The oldest frame of the RX FIFO; false when it is empty. Extended and
  // remote frames (which the filters keep out once set) are taken off the
  // FIFO and skipped, counted in skipped_frames().
  bool receive(hal::CanFrame& frame);
  // True once for each time the RX FIFO overflowed (frames were lost) since
  // the last call: the controller keeps a flag, not a count.
  bool take_rx_overflow();

  // Replaces the acceptance filters; with none, every standard data frame is
  // accepted. False, and the filters left disabled, when there are more
  // than the controller holds, an identifier or mask beyond 11 bits, or the
  // filter unit stays busy.
  bool set_filters(const hal::CanFilter* filters, std::size_t count);

  CanControllerErrors errors() const;
  CanErrorState error_state() const;
  // The error kinds the controller flagged since the last call (ESR: CRC,
  // form, stuff, bit and acknowledge errors), each counted once, and
  // cleared.
  std::uint32_t take_error_flags();

  std::uint32_t skipped_frames() const { return skipped_frames_; }

 private:
  volatile std::uint32_t& reg(std::uint32_t offset) const { return baremetal::register_at(base_, offset); }
  hal::CanStatus write_frame(std::uint32_t id_offset, std::uint32_t full_flag, const hal::CanFrame& frame);

  std::uintptr_t base_;
  std::uint32_t skipped_frames_ = 0;
};

}  // namespace cdcr::zynqmp
