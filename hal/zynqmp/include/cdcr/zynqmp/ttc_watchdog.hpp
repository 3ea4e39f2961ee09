#pragma once
// A software watchdog on one counter of a Cadence triple timer counter (TTC,
// UG1085 "Triple-timer Counters"), polled.
//
// Why software, on a TTC: QEMU 7.2's xlnx-zcu102 models neither of the
// ZynqMP's system watchdogs (nothing is mapped at the LPD SWDT, 0xFF150000,
// or the FPD SWDT, 0xFD4D0000: `info mtree` of the machine), nor CRL_APB
// (0xFF5E0000), whose RESET_CTRL and RST_LPD_TOP would reset the RPU; and it
// wires no interrupt controller to the RPU, so no timer interrupt can stop
// a core that hangs. It does model the four TTCs (`cadence_ttc`, TTC0 at
// 0xFF110000), on QEMU's virtual clock, which -icount makes deterministic.
//
// How: the TTC's first counter counts up from the last kick; expired() is
// true once the count has reached the timeout. kick() restarts the count
// from 0. Whoever polls expired() (the board's cycle loop, after every
// cycle) ends a cycle that overran the timeout, or cycles that kept
// overrunning. A loop that never comes back to the poll is not caught here;
// on silicon a match register at the timeout, its interrupt enabled,
// reaches the RPU's GIC, whose handler takes the same reset path.
//
// The timeout is compared in software, and the counter's range is 128 to 256
// times the timeout, because QEMU 7.2's TTC model hangs under -icount when
// the counter reaches an event (its interval, a match, an overflow): the
// model reschedules its timer at the same instant, rounded, and under
// -icount virtual time does not advance while it does (seen at the interval
// of a 3 ms timeout, prescaled by 8). So no event is armed (interval mode off, the match
// registers 0) and only an overflow, a hang of more than 128 timeouts,
// reaches one; its flag counts as expired too.
//
// The counter is used 16 bits wide: QEMU's model is the Zynq-7000's 16-bit
// TTC (the ZynqMP's counts 32 bits, and takes the same values).

#include <cstdint>

#include <cdcr/baremetal/mmio.hpp>

namespace cdcr::zynqmp {

// The prescaler divides the TTC clock by 2^(1 + prescale_exponent), 0..15.
struct TtcTimeout {
  bool prescaled = false;
  std::uint32_t prescale_exponent = 0;
  std::uint32_t timeout_counts = 0;  // 1..256; 0 when the timeout does not fit
};

// The counts that last `timeout_ns` (rounded down) with the finest prescaler
// that leaves the 16-bit counter at least 256 times the timeout (so at most
// 256 counts to the timeout).
inline constexpr TtcTimeout ttc_timeout(std::uint32_t clock_hz, std::uint64_t timeout_ns) {
  constexpr std::uint64_t kMaxCounts = 0x10000 / 256;
  const std::uint64_t counts = static_cast<std::uint64_t>(clock_hz) * timeout_ns / 1'000'000'000u;
  if (counts == 0) return {};
  if (counts <= kMaxCounts) return {false, 0, static_cast<std::uint32_t>(counts)};
  for (std::uint32_t exponent = 0; exponent < 16; ++exponent) {
    const std::uint64_t divided = counts >> (exponent + 1);
    if (divided <= kMaxCounts) return {true, exponent, divided == 0 ? 1u : static_cast<std::uint32_t>(divided)};
  }
  return {};
}

class TtcWatchdog {
 public:
  // `base`: the TTC; `clock_hz`: its clock (kTtcClockHz).
  constexpr TtcWatchdog(std::uintptr_t base, std::uint32_t clock_hz) : base_(base), clock_hz_(clock_hz) {}

  // Programs the timeout and starts counting from 0, the flag cleared. False,
  // with the counter left stopped, for a timeout the counter cannot take.
  bool start(std::uint64_t timeout_ns);
  // Stops the counter (a program that ends or hands over to a debugger).
  void stop();

  // Restarts the count from 0. Call it only for a cycle that completed in
  // time: a late cycle's missing kick is what makes the watchdog expire.
  void kick();
  // True once the count has reached the timeout since the last kick (or
  // start), and from then on until the next start.
  bool expired();
  // The counts to the timeout (ttc_timeout()).
  std::uint32_t timeout_counts() const { return timeout_counts_; }

  std::uint64_t timeout_ns() const { return timeout_ns_; }
  // The count since the last kick, in the counter's own steps (a test's
  // view of the hardware).
  std::uint32_t count() const;

 private:
  volatile std::uint32_t& reg(std::uint32_t offset) const { return baremetal::register_at(base_, offset); }
  std::uint32_t take_interrupt_flags();

  std::uintptr_t base_;
  std::uint32_t clock_hz_;
  std::uint64_t timeout_ns_ = 0;
  std::uint32_t timeout_counts_ = 0;
  bool expired_ = false;  // kept once seen: the overflow flag clears on read
};

}  // namespace cdcr::zynqmp
