// The Xilinx CAN driver against QEMU's emulated controllers (zynqmp.can_driver):
// can0 is driven through the runtime's interface (XilinxCan, a hal::CanBus),
// can1 on the same emulated bus plays the peer through the register-level
// controller. Every check reads back what crossed the emulated bus; nothing
// here stands in for the hardware. Prints PASS and exits 0, or names the
// first check that failed and exits 1.

#include <cstdint>

#include <cdcr/hal/can_bus.hpp>
#include <cdcr/zynqmp/can_bit_timing.hpp>
#include <cdcr/zynqmp/console.hpp>
#include <cdcr/zynqmp/xilinx_can.hpp>
#include <cdcr/zynqmp/xilinx_can_controller.hpp>
#include <cdcr/zynqmp/zcu102.hpp>

#include "checks.hpp"

namespace {

using cdcr::hal::CanFilter;
using cdcr::hal::CanFrame;
using cdcr::hal::CanStatus;
namespace zynqmp = cdcr::zynqmp;
using namespace cdcr::zynqmp_checks;  // check, check_equal, verdict

constexpr std::uint32_t kBitrate = 1'000'000;
constexpr zynqmp::CanBitTiming kTiming = zynqmp::compute_bit_timing(zynqmp::kCanReferenceClockHz, kBitrate);
static_assert(zynqmp::bitrate(kTiming, zynqmp::kCanReferenceClockHz) == kBitrate,
              "1 Mbit/s is exact from the 24 MHz reference clock");
static_assert(kTiming.prescaler == 3 && kTiming.tseg1 == 6 && kTiming.tseg2 == 1,
              "8 quanta of 125 ns, sampled at 87.5 %");

// A depth below the controller's FIFO, so that the overflow test also
// exercises a ring that fills before the FIFO is drained.
constexpr std::size_t kRxQueueDepth = 16;

zynqmp::XilinxCan<kRxQueueDepth> can0{zynqmp::kCan0Base};
zynqmp::XilinxCanController peer{zynqmp::kCan1Base};

CanFrame make_frame(std::uint32_t id, std::uint8_t dlc, std::uint8_t first_byte) {
  CanFrame frame;
  frame.id = id;
  frame.dlc = dlc;
  for (std::uint8_t i = 0; i < dlc; ++i) frame.data[i] = static_cast<std::uint8_t>(first_byte + 17 * i);
  return frame;
}

bool same_frame(const CanFrame& a, const CanFrame& b) {
  if (a.id != b.id || a.dlc != b.dlc) return false;
  for (std::uint8_t i = 0; i < a.dlc; ++i) {
    if (a.data[i] != b.data[i]) return false;
  }
  return true;
}

// Every frame can0 has received, until the ring and the FIFO are empty.
int drain_can0() {
  int frames = 0;
  CanFrame frame;
  while (can0.receive(frame) == CanStatus::ok) ++frames;
  return frames;
}

void check_bit_timing() {
  const zynqmp::CanBitTiming held = can0.controller().bit_timing();
  check_equal(held.prescaler, kTiming.prescaler, "BRPR holds the prescaler");
  check_equal(held.tseg1, kTiming.tseg1, "BTR holds TS1");
  check_equal(held.tseg2, kTiming.tseg2, "BTR holds TS2");
  check_equal(held.sjw, kTiming.sjw, "BTR holds SJW");
  check_equal(zynqmp::bitrate(held, zynqmp::kCanReferenceClockHz), kBitrate, "bitrate from the registers");
  print("bit timing held: prescaler ", held.prescaler, ", 1 + ", held.tseg1, " + ", held.tseg2, " quanta, SJW ",
        held.sjw, ": ", zynqmp::bitrate(held, zynqmp::kCanReferenceClockHz), " bit/s from 24 MHz\n");
  check(!is_valid(zynqmp::CanBitTiming{0, 6, 1, 1}), "a prescaler of 0 is refused");
  check(!is_valid(zynqmp::CanBitTiming{3, 17, 1, 1}), "a TS1 of 17 quanta is refused");
  check(!is_valid(zynqmp::CanBitTiming{3, 6, 9, 1}), "a TS2 of 9 quanta is refused");
}

// can0 -> can1 through the TX FIFO, and can1 -> can0 into the ring, every
// data length, every byte position.
void check_transfer() {
  for (std::uint8_t dlc = 0; dlc <= 8; ++dlc) {
    const CanFrame sent = make_frame(0x100u + dlc, dlc, static_cast<std::uint8_t>(0xA0 + dlc));
    check(can0.send(sent) == CanStatus::ok, "can0 sends");
    CanFrame received;
    check(peer.receive(received), "can1 receives what can0 sent");
    check(same_frame(received, sent), "can1 receives the frame can0 sent, byte for byte");
  }
  const CanFrame highest = make_frame(0x7FF, 8, 0xFF);
  check(can0.send(highest) == CanStatus::ok, "can0 sends identifier 0x7FF");
  CanFrame received;
  check(peer.receive(received) && same_frame(received, highest), "identifier 0x7FF crosses intact");

  for (std::uint8_t dlc = 0; dlc <= 8; ++dlc) {
    const CanFrame sent = make_frame(0x200u + dlc, dlc, static_cast<std::uint8_t>(0x30 + dlc));
    check(peer.transmit(sent) == CanStatus::ok, "can1 sends");
    check(can0.receive(received) == CanStatus::ok, "can0 receives what can1 sent");
    check(same_frame(received, sent), "can0 receives the frame can1 sent, byte for byte");
  }
  check(can0.receive(received) == CanStatus::empty, "nothing more arrives at can0");
  check(!peer.receive(received), "nothing more arrives at can1");

  const CanFrame urgent = make_frame(0x010, 2, 0x55);
  check(peer.transmit_high_priority(urgent) == CanStatus::ok, "can1 sends through the high-priority buffer");
  check(can0.receive(received) == CanStatus::ok && same_frame(received, urgent),
        "can0 receives the high-priority frame");

  check(can0.send(make_frame(0x800, 1, 0)) == CanStatus::invalid_frame, "a 12-bit identifier is refused");
  CanFrame too_long = make_frame(0x123, 8, 0);
  too_long.dlc = 9;
  check(can0.send(too_long) == CanStatus::invalid_frame, "a data length of 9 is refused");
  check_equal(can0.error_counters().tx_dropped, 2, "refused frames are counted as dropped");
  check(!peer.receive(received), "refused frames never reach the bus");
}

// The runtime's filters, in the controller's acceptance filters.
void check_filters() {
  const CanFilter filters[] = {{0x100, 0x700}, {0x321, 0x7FF}, {0x040, 0x7F0}, {0x7FF, 0x7FF}};
  check(can0.set_filters(filters, 4), "four filters fit the controller");
  const std::uint32_t ids[] = {0x105, 0x1FF, 0x200, 0x321, 0x320, 0x322, 0x04F, 0x050, 0x7FF, 0x7FE, 0x000};
  const bool accepted[] = {true, true, false, true, false, false, true, false, true, false, false};
  for (std::uint32_t id : ids) check(peer.transmit(make_frame(id, 1, 0x11)) == CanStatus::ok, "can1 sends");
  CanFrame received;
  for (std::size_t i = 0; i < sizeof(ids) / sizeof(ids[0]); ++i) {
    if (!accepted[i]) continue;
    check(can0.receive(received) == CanStatus::ok, "an accepted frame arrives");
    check_equal(received.id, ids[i], "accepted frames arrive in order, rejected ones not at all");
  }
  check(can0.receive(received) == CanStatus::empty, "no rejected frame arrives");

  const CanFilter five[] = {{0x1, 0x7FF}, {0x2, 0x7FF}, {0x3, 0x7FF}, {0x4, 0x7FF}, {0x5, 0x7FF}};
  check(!can0.set_filters(five, 5), "a fifth filter is refused");
  const CanFilter wide_id[] = {{0x800, 0x7FF}};
  check(!can0.set_filters(wide_id, 1), "a filter identifier beyond 11 bits is refused");
  const CanFilter wide_mask[] = {{0x100, 0xFFF}};
  check(!can0.set_filters(wide_mask, 1), "a filter mask beyond 11 bits is refused");
  // A refused set leaves the filters that were there.
  check(peer.transmit(make_frame(0x200, 1, 0)) == CanStatus::ok && peer.transmit(make_frame(0x321, 1, 0)) == CanStatus::ok,
        "can1 sends");
  check(can0.receive(received) == CanStatus::ok && received.id == 0x321, "a refused set keeps the filters");
  check(can0.receive(received) == CanStatus::empty, "a refused set keeps rejecting");

  const CanFilter exact[] = {{0x0AB, 0x7FF}};
  check(can0.set_filters(exact, 1), "one exact filter");
  check(peer.transmit(make_frame(0x0AA, 1, 0)) == CanStatus::ok && peer.transmit(make_frame(0x0AB, 1, 0)) == CanStatus::ok,
        "can1 sends");
  check(can0.receive(received) == CanStatus::ok && received.id == 0x0AB, "the exact filter passes its identifier");
  check(can0.receive(received) == CanStatus::empty, "the exact filter rejects its neighbour");

  check(can0.set_filters(nullptr, 0), "no filters");
  check(peer.transmit(make_frame(0x5A5, 1, 0)) == CanStatus::ok, "can1 sends");
  check(can0.receive(received) == CanStatus::ok && received.id == 0x5A5, "with no filter every frame is accepted");
}

// More frames than the controller's RX FIFO holds while nobody reads: the
// first 64 arrive in order, the overflow is counted once, and the driver
// goes on receiving.
void check_rx_overflow() {
  constexpr std::uint32_t kSent = zynqmp::kXilinxCanFifoFrames + 6;
  for (std::uint32_t i = 0; i < kSent; ++i) {
    check(peer.transmit(make_frame(0x300 + i, 2, static_cast<std::uint8_t>(i))) == CanStatus::ok, "can1 floods");
  }
  check_equal(can0.error_counters().rx_overruns, 0, "no overrun before can0 looks");
  CanFrame received;
  std::uint32_t arrived = 0;
  bool in_order = true;
  while (can0.receive(received) == CanStatus::ok) {
    in_order = in_order && received.id == 0x300 + arrived && received.data[0] == static_cast<std::uint8_t>(arrived);
    ++arrived;
  }
  print("RX flood: ", kSent, " frames sent unread, ", arrived, " received, ", can0.error_counters().rx_overruns,
        " overflow counted\n");
  check_equal(arrived, zynqmp::kXilinxCanFifoFrames, "the RX FIFO's 64 frames arrive");
  check(in_order, "the frames the FIFO held arrive in order");
  check_equal(can0.error_counters().rx_overruns, 1, "the overflow is counted");
  can0.poll();
  check_equal(can0.error_counters().rx_overruns, 1, "the overflow is counted once");

  check(peer.transmit(make_frame(0x444, 3, 0x44)) == CanStatus::ok, "can1 sends after the flood");
  check(can0.receive(received) == CanStatus::ok && received.id == 0x444, "can0 receives after the overflow");
  check_equal(static_cast<std::uint32_t>(drain_can0()), 0, "nothing left behind");
}

void check_error_state() {
  const zynqmp::CanControllerErrors errors = can0.controller().errors();
  check(errors.state == zynqmp::CanErrorState::error_active, "can0 is error-active on the bus");
  check_equal(errors.transmit_error_count, 0, "TEC after clean traffic");
  check_equal(errors.receive_error_count, 0, "REC after clean traffic");
  check_equal(can0.error_counters().bus_errors, 0, "no error frames on a clean bus");
}

// In loopback the controller hears itself and puts nothing on the bus. It
// also takes another bit timing, every field of it other than 1 (a field of
// 1 is 0 in the register, wherever it lands): 125 kbit/s, 16 quanta.
void check_loopback() {
  zynqmp::XilinxCanController looped{zynqmp::kCan1Base};
  constexpr zynqmp::CanBitTiming kSlowTiming{12, 11, 4, 3};
  static_assert(zynqmp::bitrate(kSlowTiming, zynqmp::kCanReferenceClockHz) == 125'000, "125 kbit/s");
  check(looped.start(kSlowTiming, zynqmp::CanMode::loopback), "can1 enters loopback mode");
  const zynqmp::CanBitTiming held = looped.bit_timing();
  check_equal(held.prescaler, kSlowTiming.prescaler, "BRPR holds another prescaler");
  check_equal(held.tseg1, kSlowTiming.tseg1, "BTR holds another TS1");
  check_equal(held.tseg2, kSlowTiming.tseg2, "BTR holds another TS2");
  check_equal(held.sjw, kSlowTiming.sjw, "BTR holds another SJW");
  const CanFrame sent = make_frame(0x0F0, 4, 0x0F);
  check(looped.transmit(sent) == CanStatus::ok, "can1 sends in loopback");
  CanFrame received;
  check(looped.receive(received) && same_frame(received, sent), "can1 receives its own frame in loopback");
  check(can0.receive(received) == CanStatus::empty, "a loopback frame stays off the bus");
  check(looped.errors().state == zynqmp::CanErrorState::error_active, "loopback is out of configuration mode");
}

}  // namespace

int main() {
  zynqmp::console_write("zynqmp can driver: can0 through hal::CanBus, can1 as its peer\n");
  check(can0.start(kTiming), "can0 starts at 1 Mbit/s");
  check(peer.start(kTiming), "can1 starts at 1 Mbit/s");
  check(can0.controller().errors().state == zynqmp::CanErrorState::error_active, "can0 leaves configuration mode");
  check_bit_timing();
  check_transfer();
  check_filters();
  check_rx_overflow();
  check_error_state();
  check_loopback();
  return verdict();
}
